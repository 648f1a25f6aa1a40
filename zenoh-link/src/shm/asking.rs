//! "Which of my buffers do you still hold?": how a writer learns that its live readers
//! let go of a buffer that a killed reader still counts in (reclaim.rs).
//!
//! Zenoh's count of a pool buffer's holders says how many there are, not who. With
//! several readers of the same frames (one camera, many consumer parts) a killed
//! reader's count stays in every buffer it was sent, and the other readers, alive,
//! were sent the same buffers. So the writer asks them, and a buffer comes back once
//! every session it was sent to is either gone (its process ended) or a ferroc reader
//! that answered that it is done with it. A session that does not answer (a Python
//! client, bare Zenoh, a part whose `/proc` the writer cannot see) is never done: what
//! it was sent stays, as before.
//!
//! What "done" must mean, for a buffer never to be written while a live reader can
//! still see it: the reader holds no value read from it **and** never will again.
//! A value still on its way (in the writer's send queue, a socket, or Zenoh's receive
//! queue of the reader) is not held yet, so the reader alone cannot say that. Hence:
//!
//! - The writer stamps each value it sends in shared memory with its publisher's id
//!   and the next number of that publisher (Zenoh's `SourceInfo`, a field of the
//!   message any client may ignore; [`Order`]). Numbers are taken and values put under
//!   one lock, and one publisher's values reach a reader in order (one priority, one
//!   transport), so once a reader has seen number *n*, every value numbered up to *n*
//!   has reached it or never will (a dropped value is not held by anyone).
//! - A reader notes, per publisher, the last number it has seen and every number a
//!   value it holds came with ([`Receipts`]): a value it decoded in place keeps its
//!   [`Receipt`] as long as it lives.
//! - Asked (a `get` on `ferroc/APP/held/WRITER`, every part has a queryable on
//!   `ferroc/APP/held/*`), it answers with both, or that it does not receive from that
//!   writer at all (then nothing the writer sent ever reached it).
//! - The writer counts a reader done with a buffer when for every time it sent it the
//!   answer's last number is at least the send's and the send is not among the held
//!   ones. That is a fact that stays true, whenever the answer arrives.
//!
//! The writer asks only while some buffer waits for a live reader's word (a reader it
//! was sent to is gone, another is not known to be done), at most every
//! [`ASK_EVERY`], one question at a time.

// Without shared memory only the types below stay, unused: nothing is asked.
#![cfg_attr(not(feature = "shared-memory"), allow(dead_code))]

use serde::{Deserialize, Serialize};
use std::time::Duration;

/// How often at most a writer asks its readers what they hold.
pub const ASK_EVERY: Duration = Duration::from_millis(250);

/// How long a question waits for its answers.
pub(crate) const ASK_TIMEOUT: Duration = Duration::from_secs(2);

/// A writer's question: what of `writer`'s (its session's Zenoh id) do you hold?
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Eq)]
pub(crate) struct Question {
    pub writer: String,
}

/// A reader's answer.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Eq, Default)]
pub(crate) struct Answer {
    /// The reader's session (its Zenoh id, as the writer's transport events name it).
    pub reader: String,
    /// Whether it receives from the writer's part at all.
    pub receives: bool,
    /// Per publisher of the writer it has seen a value of.
    pub publishers: Vec<Seen>,
}

/// What a reader has seen of one publisher.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq, Eq, Default)]
pub(crate) struct Seen {
    /// The publisher's entity id in the writer's session.
    pub publisher: u32,
    /// The last number it has seen.
    pub last: u32,
    /// The numbers of the values it still holds.
    pub held: Vec<u32>,
}

/// Whether number `a` is `b` or came after it (numbers wrap; one more than 2³¹ apart
/// read as *before*, which only keeps a buffer longer).
pub(crate) fn at_or_after(a: u32, b: u32) -> bool {
    a.wrapping_sub(b) < 1 << 31
}

impl Answer {
    /// Whether the reader is done with a buffer sent as `sends` (publisher, number).
    pub(crate) fn done_with(&self, sends: &[(u32, u32)]) -> bool {
        if !self.receives {
            return true;
        }
        !sends.is_empty()
            && sends.iter().all(|(publisher, number)| {
                self.publishers.iter().any(|s| {
                    s.publisher == *publisher
                        && at_or_after(s.last, *number)
                        && !s.held.contains(number)
                })
            })
    }
}

/// A buffer a reader reads in place, with the receipt of the message it came in
/// (while it lives, the reader says it holds that message's number).
pub(crate) struct Read<T> {
    pub(crate) bytes: T,
    pub(crate) _receipt: Option<std::sync::Arc<Receipt>>,
}

impl<T> Read<T> {
    /// `bytes`, keeping `receipt`.
    pub(crate) fn new(bytes: T, receipt: &Option<std::sync::Arc<Receipt>>) -> Self {
        let _receipt = receipt.clone();
        Read { bytes, _receipt }
    }
}

impl<T: AsRef<[u8]>> AsRef<[u8]> for Read<T> {
    fn as_ref(&self) -> &[u8] {
        self.bytes.as_ref()
    }
}

#[cfg(feature = "shared-memory")]
pub(crate) use with_shm::*;

#[cfg(feature = "shared-memory")]
mod with_shm {
    use super::{at_or_after, Answer, Question, Seen, ASK_TIMEOUT};
    use crate::shm::reclaim::Ledger;
    use std::collections::BTreeSet;
    use std::sync::{Arc, Mutex, OnceLock};
    use zenoh::bytes::ZBytes;
    use zenoh::key_expr::OwnedKeyExpr;
    use zenoh::pubsub::Publisher;
    use zenoh::query::{ConsolidationMode, Query, QueryTarget, Queryable};
    use zenoh::sample::{Sample, SourceInfo};
    use zenoh::session::EntityGlobalId;
    use zenoh::{Session, Wait};

    /// The numbers one publisher stamps its shared-memory values with.
    #[derive(Default)]
    pub(crate) struct Order {
        next: Mutex<u32>,
        /// The publisher's id, asked of Zenoh once (it goes through the session).
        id: OnceLock<EntityGlobalId>,
    }

    impl Order {
        /// Puts `bytes` with `attachment` on `publisher`; stamped with the publisher's
        /// next number when `stamp` (a value in shared memory), under this order's lock
        /// so that numbers and puts keep one order. The send (publisher, number) if
        /// stamped.
        pub(crate) fn put(
            &self,
            publisher: &Publisher<'static>,
            bytes: ZBytes,
            attachment: ZBytes,
            stamp: bool,
        ) -> (zenoh::Result<()>, Option<(u32, u32)>) {
            let put = publisher.put(bytes).attachment(attachment);
            if !stamp {
                return (put.wait(), None);
            }
            let id = *self.id.get_or_init(|| publisher.id());
            let mut next = lock(&self.next);
            let number = *next;
            *next = next.wrapping_add(1);
            let put = put.source_info(SourceInfo::new(id, number)).wait();
            (put, Some((id.eid(), number)))
        }
    }

    /// What one reading connection has seen and holds, per publisher of its writers.
    pub(crate) struct Receipts {
        /// The parts it receives from.
        writers: BTreeSet<String>,
        seen: Arc<Mutex<Vec<Heard>>>,
    }

    /// What a reader has seen of one publisher. Searched in a list, not hashed: a
    /// reader hears a few publishers and holds a few numbers of each at a time (its
    /// inputs' values), and every value arrives and is dropped through here in Zenoh's
    /// receive thread (SipHash of the id and the number was ~1,100 instructions a
    /// value; bench/README.md, b3-parts).
    struct Heard {
        publisher: EntityGlobalId,
        last: u32,
        /// How many values it holds per number.
        held: Vec<(u32, usize)>,
    }

    /// Kept by a value read in place from a stamped message: while it lives, the
    /// reader says it holds that number.
    pub(crate) struct Receipt {
        seen: Arc<Mutex<Vec<Heard>>>,
        publisher: EntityGlobalId,
        number: u32,
    }

    impl Drop for Receipt {
        fn drop(&mut self) {
            let mut seen = lock(&self.seen);
            let Some(p) = seen.iter_mut().find(|p| p.publisher == self.publisher) else {
                return;
            };
            if let Some(at) = p.held.iter().position(|(n, _)| *n == self.number) {
                p.held[at].1 -= 1;
                if p.held[at].1 == 0 {
                    p.held.swap_remove(at);
                }
            }
        }
    }

    impl Receipts {
        /// For a connection receiving from the parts `writers`.
        pub(crate) fn new(writers: impl IntoIterator<Item = String>) -> Receipts {
            Receipts {
                writers: writers.into_iter().collect(),
                seen: Arc::default(),
            }
        }

        /// `sample` arrived: its number is seen, and held until the receipt (kept by
        /// whatever reads the value in place) is dropped. `None` if it is not stamped.
        pub(crate) fn arrived(&self, sample: &Sample) -> Option<Arc<Receipt>> {
            let info = sample.source_info()?;
            Some(self.arrived_from(*info.source_id(), info.source_sn()))
        }

        /// [`arrived`](Self::arrived) of the value numbered `number` by `publisher`.
        pub(crate) fn arrived_from(&self, publisher: EntityGlobalId, number: u32) -> Arc<Receipt> {
            let mut seen = lock(&self.seen);
            let at = match seen.iter().position(|p| p.publisher == publisher) {
                Some(at) => at,
                None => {
                    seen.push(Heard {
                        publisher,
                        last: number,
                        held: Vec::new(),
                    });
                    seen.len() - 1
                }
            };
            let p = &mut seen[at];
            if at_or_after(number, p.last) {
                p.last = number;
            }
            match p.held.iter_mut().find(|(n, _)| *n == number) {
                Some((_, count)) => *count += 1,
                None => p.held.push((number, 1)),
            }
            drop(seen);
            Arc::new(Receipt {
                seen: Arc::clone(&self.seen),
                publisher,
                number,
            })
        }

        /// The answer to `question`, asked about the part `writer`, by `reader`.
        pub(crate) fn answer(&self, reader: &str, writer: &str, question: &Question) -> Answer {
            let seen = lock(&self.seen);
            let publishers = (seen.iter())
                .filter(|p| p.publisher.zid().to_string() == question.writer)
                .map(|p| Seen {
                    publisher: p.publisher.eid(),
                    last: p.last,
                    held: p.held.iter().map(|(n, _)| *n).collect(),
                })
                .collect();
            Answer {
                reader: reader.to_owned(),
                receives: self.writers.contains(writer),
                publishers,
            }
        }
    }

    /// The queryable on `key` (`ferroc/APP/held/*`, the last chunk the asking
    /// writer's part) that answers for `receipts`.
    pub(crate) fn answering(
        session: &Session,
        key: OwnedKeyExpr,
        receipts: Arc<Receipts>,
    ) -> zenoh::Result<Option<Queryable<()>>> {
        let reader = session.zid().to_string();
        let queryable = session
            .declare_queryable(key)
            .callback(move |query: Query| {
                let Some(writer) = query.key_expr().as_str().rsplit('/').next() else {
                    return;
                };
                let question = query.payload().map(|p| p.to_bytes());
                let Some(question) = question.and_then(|q| postcard::from_bytes(&q).ok()) else {
                    return;
                };
                let answer = receipts.answer(&reader, writer, &question);
                let Ok(bytes) = postcard::to_allocvec(&answer) else {
                    return;
                };
                let _ = query.reply(query.key_expr().clone(), bytes).wait();
            })
            .wait()?;
        Ok(Some(queryable))
    }

    /// Asks the readers on `key` (`ferroc/APP/held/PART`) of `session` what they hold
    /// of it; their answers go to `ledger` for its session number `asked`. The ledger
    /// hears when the question is over.
    pub(crate) fn ask(session: &Session, key: &OwnedKeyExpr, ledger: &Arc<Ledger>, asked: u64) {
        struct Over(Arc<Ledger>);
        impl Drop for Over {
            fn drop(&mut self) {
                self.0.asked();
            }
        }
        let question = Question {
            writer: session.zid().to_string(),
        };
        let over = Over(Arc::clone(ledger));
        let Ok(bytes) = postcard::to_allocvec(&question) else {
            return;
        };
        let _ = session
            .get(key.clone())
            .payload(bytes)
            .target(QueryTarget::All)
            .consolidation(ConsolidationMode::None)
            .timeout(ASK_TIMEOUT)
            .callback(move |reply| {
                let ledger = &over.0;
                let Ok(sample) = reply.result() else {
                    return;
                };
                // An answer counts only for the session that sent it (Zenoh says which).
                let replier = reply.replier_id().map(|id| id.zid().to_string());
                match postcard::from_bytes::<Answer>(&sample.payload().to_bytes()) {
                    Ok(answer) if replier.as_ref() == Some(&answer.reader) => {
                        ledger.answered(asked, &answer);
                    }
                    _ => {}
                }
            })
            .wait();
    }

    fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
        m.lock().unwrap_or_else(|e| e.into_inner())
    }
}

#[cfg(all(test, feature = "shared-memory"))]
mod tests {
    use super::*;
    use zenoh::config::ZenohId;
    use zenoh::session::EntityGlobalId;

    fn publisher(zid: u8, eid: u32) -> EntityGlobalId {
        EntityGlobalId::new(ZenohId::try_from(&[zid][..]).unwrap(), eid)
    }

    /// (last, held numbers sorted) that the reader answers for publisher `eid`.
    fn heard(receipts: &Receipts, writer: &EntityGlobalId, eid: u32) -> Option<(u32, Vec<u32>)> {
        let question = Question {
            writer: writer.zid().to_string(),
        };
        let answer = receipts.answer("reader", "w", &question);
        assert!(answer.receives);
        let seen = answer.publishers.into_iter().find(|s| s.publisher == eid)?;
        let mut held = seen.held;
        held.sort_unstable();
        Some((seen.last, held))
    }

    #[test]
    fn a_number_is_held_while_any_receipt_of_it_lives_and_the_last_never_goes_back() {
        let receipts = Receipts::new(["w".to_owned()]);
        let (p, q, other) = (publisher(1, 7), publisher(1, 8), publisher(2, 7));
        let five = receipts.arrived_from(p, 5);
        let five_again = receipts.arrived_from(p, 5); // a second link of the same value
        let six = receipts.arrived_from(p, 6);
        let q_one = receipts.arrived_from(q, 1);
        let elsewhere = receipts.arrived_from(other, 9);
        assert_eq!(heard(&receipts, &p, 7), Some((6, vec![5, 6])));
        assert_eq!(heard(&receipts, &q, 8), Some((1, vec![1])));
        drop(five);
        assert_eq!(heard(&receipts, &p, 7), Some((6, vec![5, 6])), "one left");
        drop(five_again);
        assert_eq!(heard(&receipts, &p, 7), Some((6, vec![6])));
        // An older number (wrapping) does not move the last one back.
        let old = receipts.arrived_from(p, u32::MAX);
        assert_eq!(heard(&receipts, &p, 7), Some((6, vec![6, u32::MAX])));
        drop((six, old, q_one));
        assert_eq!(heard(&receipts, &p, 7), Some((6, vec![])));
        assert_eq!(heard(&receipts, &q, 8), Some((1, vec![])));
        // Another writer's session is not in this writer's answer.
        assert_eq!(heard(&receipts, &other, 7), Some((9, vec![9])));
        drop(elsewhere);
    }
}

/// Without shared memory nothing is stamped, held or asked.
#[cfg(not(feature = "shared-memory"))]
pub(crate) use without_shm::*;

#[cfg(not(feature = "shared-memory"))]
mod without_shm {
    use std::sync::Arc;
    use zenoh::bytes::ZBytes;
    use zenoh::key_expr::OwnedKeyExpr;
    use zenoh::pubsub::Publisher;
    use zenoh::query::Queryable;
    use zenoh::sample::Sample;
    use zenoh::{Session, Wait};

    /// Nothing to number: nothing is asked.
    #[derive(Default)]
    pub(crate) struct Order {
        _nothing: (),
    }

    impl Order {
        pub(crate) fn put(
            &self,
            publisher: &Publisher<'static>,
            bytes: ZBytes,
            attachment: ZBytes,
            _stamp: bool,
        ) -> (zenoh::Result<()>, Option<(u32, u32)>) {
            (publisher.put(bytes).attachment(attachment).wait(), None)
        }
    }

    pub(crate) struct Receipts;

    pub(crate) enum Receipt {}

    impl Receipts {
        pub(crate) fn new(_: impl IntoIterator<Item = String>) -> Receipts {
            Receipts
        }

        pub(crate) fn arrived(&self, _: &Sample) -> Option<Arc<Receipt>> {
            None
        }
    }

    pub(crate) fn answering(
        _: &Session,
        _: OwnedKeyExpr,
        _: Arc<Receipts>,
    ) -> zenoh::Result<Option<Queryable<()>>> {
        Ok(None)
    }
}
