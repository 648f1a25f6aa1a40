//! The buffers of readers that are gone come back to the pool.
//!
//! Zenoh counts the holders of a pool buffer in shared memory: each process that
//! maps it adds one per value it holds and takes it off when it lets go. Zenoh's safe
//! collection reuses a buffer only when the count is zero, so a reader killed while it
//! holds values (SIGKILL, a crash) keeps its buffers counted for ever: they leak.
//! Zenoh's watchdog does notice that nobody confirms them any more, but only its
//! *unsafe* collection acts on that, and it acts on a timer: it would also take the
//! buffers of a live reader whose watchdog thread did not run for 100 ms.
//!
//! This file keeps a ledger of the buffers this part sent instead, and gives a buffer
//! back by a rule about processes, not time:
//!
//! - Right after each put of a buffer, it notes every Zenoh session this part's session
//!   has a transport to (on this computer or not; Zenoh tells a new transport before a
//!   value can take it). Only those can hold the buffer: Zenoh hands a value only to
//!   sessions it has a transport to, when the put routes it, and ferroc's parts are
//!   peers that do not forward each other's values.
//! - The ledger holds one reference of its own to every buffer it lists. A buffer that
//!   only the ledger holds is dropped from it, and Zenoh's safe collection takes it as
//!   before.
//! - A buffer that others still hold comes back when, for every session it was sent
//!   to, the transport is closed *and* the process behind the session no longer exists
//!   ([`process`]: a ferroc part's Zenoh id names its process), since [`GRACE`] at
//!   least; when nothing in this part still holds it (no output's lent buffer); and
//!   when the session it was sent by is still the part's, or saw all of them go before
//!   it closed. Then its chunk goes back to the backend ([`Chunks::free_held`]); the
//!   ledger keeps its reference for good, so the count never reaches zero and Zenoh
//!   never frees that chunk a second time.
//!
//! Why a live reader never loses a buffer it still reads, however slow it is: its
//! process exists, so the buffer stays; nothing about its speed, its watchdog thread
//! or its transport (which a process starved for longer than the lease loses and
//! opens again) is asked. A session that is not a ferroc part, or whose process this
//! part cannot look up (another PID namespace, no `/proc`), never counts as gone: what
//! it was sent stays, as before.
//!
//! Several readers of the same buffers (one camera, many consumer parts): Zenoh's
//! count does not say who holds what, so a killed reader's share cannot be told from
//! a live one's by the count. The writer asks its live readers instead
//! ([`asking`](super::asking)): a session it was sent to also counts as gone for a
//! buffer once it answered that it is done with it (holds nothing read from it and
//! has seen it go by, so none of it is still on its way). A buffer comes back only if
//! at least one of its sessions is really gone (otherwise nobody should still count
//! in it) and every other one answered so. What stays counted: a buffer also sent to
//! a session that lives on and does not answer (a Python client, bare Zenoh) comes
//! back only once that session's process is gone too.
//!
//! Why [`GRACE`]: a transport that closed may still hand its last messages to its
//! socket for a moment; a second is far more than that takes.

use super::asking::{Answer, ASK_EVERY};
use super::counting::Chunks;
use super::process;
use std::collections::{BTreeSet, HashMap};
use std::sync::{Mutex, Weak};
use std::time::{Duration, Instant};
use zenoh::shm::{zshmmut, ShmBuf, ZShm};

/// How long every session a buffer was sent to must have been gone before the buffer
/// comes back (see the module documentation).
pub const GRACE: Duration = Duration::from_secs(1);

/// The ledger of the buffers one pool sent and others may still hold.
#[derive(Default)]
pub(crate) struct Ledger {
    state: Mutex<State>,
}

#[derive(Default)]
struct State {
    /// By the address of the buffer's first byte.
    entries: HashMap<usize, Entry>,
    /// References to the buffers given back while gone readers still counted in them:
    /// kept, so that Zenoh's count of them never reaches zero.
    kept: Vec<ZShm>,
    /// The session the part sends with now (a number, one more per session), `None`
    /// while it has none.
    session: Option<u64>,
    sessions: u64,
    /// The sessions this part's session has a transport to now, as Zenoh's transport
    /// events say (an opening transport is told before any value can take it).
    present: BTreeSet<String>,
    /// How many buffers came back from gone sessions so far.
    given_back: u64,
    /// Whether a question to the readers is on its way, and when the last one went.
    asking: bool,
    asked_at: Option<Instant>,
}

struct Entry {
    /// The ledger's own reference.
    held: ZShm,
    record: Record,
}

/// What the ledger knows of a buffer besides its reference.
pub(crate) struct Record {
    /// The output's lent buffer, while the output still holds it.
    lent: Option<Weak<()>>,
    sent: Sent,
    /// Since when every session it was sent to is gone.
    gone_since: Option<Instant>,
}

/// Whom a buffer was sent to.
enum Sent {
    /// Nobody yet.
    Not,
    /// By the session numbered `session`: the sessions it had a transport to, after
    /// each put.
    To {
        session: u64,
        peers: BTreeSet<String>,
        /// Each time it was sent: the publisher and its number (asking.rs).
        sends: Vec<(u32, u32)>,
        /// The peers that answered they are done with it.
        done: BTreeSet<String>,
    },
    /// By a session since closed, which saw every session it was sent to go first.
    Left,
    /// By a session since closed, while some session it was sent to was still there:
    /// nobody can tell who holds it.
    Unknown,
}

/// The address of a buffer's first byte, its name in the ledger.
pub(crate) fn address(bytes: &[u8]) -> usize {
    super::Pool::address(bytes)
}

impl Ledger {
    /// The part opened a new session to send with.
    pub(crate) fn attach(&self) {
        let mut s = lock(&self.state);
        s.sessions += 1;
        s.session = Some(s.sessions);
    }

    /// The part closed its session: a buffer whose every session was already gone
    /// can still come back, no other can.
    pub(crate) fn detach(&self) {
        let mut s = lock(&self.state);
        let State {
            entries,
            session,
            present,
            ..
        } = &mut *s;
        for e in entries.values_mut() {
            let left = e.record.readers_gone(*session, present);
            if let Sent::To { .. } = e.record.sent {
                e.record.sent = if left { Sent::Left } else { Sent::Unknown };
            }
        }
        s.session = None;
        s.present.clear();
    }

    /// A transport of this part's session to the session `peer` opened (`open`) or
    /// closed, at `now`.
    pub(crate) fn transport(&self, peer: String, open: bool, now: Instant) {
        let mut s = lock(&self.state);
        if open {
            s.present.insert(peer);
            return;
        }
        s.present.remove(&peer);
        let State {
            entries,
            session,
            present,
            ..
        } = &mut *s;
        for e in entries.values_mut() {
            if e.record.gone(*session, present) {
                e.record.gone_since.get_or_insert(now);
            }
        }
    }

    /// Lists `buffer` (a reference of its own), about to be sent; `lent` while an
    /// output holds it.
    pub(crate) fn track(&self, buffer: &ZShm, lent: Option<Weak<()>>) {
        let mut s = lock(&self.state);
        let entry = s.entries.entry(address(buffer)).or_insert_with(|| Entry {
            held: buffer.clone(),
            record: Record {
                lent: None,
                sent: Sent::Not,
                gone_since: None,
            },
        });
        if lent.is_some() {
            entry.record.lent = lent;
        }
    }

    /// The buffers at `addresses` were just put (stamped `send`: publisher, number):
    /// every session this part's session has a transport to may hold them.
    pub(crate) fn sent(&self, addresses: &[usize], send: Option<(u32, u32)>) {
        let mut s = lock(&self.state);
        let State {
            entries,
            session,
            present: peers,
            ..
        } = &mut *s;
        let session = *session;
        for address in addresses {
            let Some(entry) = entries.get_mut(address) else {
                continue;
            };
            let record = &mut entry.record;
            record.sent = match (std::mem::replace(&mut record.sent, Sent::Unknown), session) {
                (Sent::Not, Some(now)) => Sent::To {
                    session: now,
                    peers: peers.clone(),
                    sends: send.into_iter().collect(),
                    done: BTreeSet::new(),
                },
                (
                    Sent::To {
                        session,
                        peers: mut known,
                        mut sends,
                        ..
                    },
                    Some(now),
                ) if session == now => {
                    known.extend(peers.iter().cloned());
                    sends.extend(send);
                    Sent::To {
                        session,
                        peers: known,
                        sends,
                        done: BTreeSet::new(),
                    }
                }
                _ => Sent::Unknown,
            };
            record.gone_since = None;
        }
    }

    /// Takes the ledger's reference to the buffer at `address` away, so that its output
    /// can tell whether anybody else holds it; `None` if it is not listed.
    pub(crate) fn untrack(&self, address: usize) -> Option<Record> {
        let entry = lock(&self.state).entries.remove(&address)?;
        Some(entry.record)
    }

    /// Lists again a buffer [`untrack`](Self::untrack) took away (others hold it).
    pub(crate) fn retrack(&self, buffer: &ZShm, record: Record) {
        let held = buffer.clone();
        lock(&self.state)
            .entries
            .insert(address(buffer), Entry { held, record });
    }

    /// Drops the buffers only the ledger holds (Zenoh's safe collection then takes
    /// them), and gives back to `chunks` every buffer whose
    /// sessions have all been gone for [`GRACE`] at `now`. How many came back (of
    /// both kinds).
    pub(crate) fn reclaim(&self, now: Instant, chunks: &Chunks) -> usize {
        let mut s = lock(&self.state);
        let State {
            entries,
            kept,
            session,
            present,
            ..
        } = &mut *s;
        let (session, present) = (*session, &*present);
        let (mut back, mut released) = (Vec::new(), 0);
        entries.retain(|address, e| {
            if e.only_here() {
                released += 1;
                return false;
            }
            if !e.record.gone(session, present) {
                e.record.gone_since = None;
                return true;
            }
            let since = *e.record.gone_since.get_or_insert(now);
            if now.saturating_duration_since(since) < GRACE || !chunks.free_held(*address) {
                return true;
            }
            back.push(e.held.clone());
            false
        });
        let count = back.len();
        kept.extend(back);
        s.given_back += count as u64;
        count + released
    }
}

impl Ledger {
    /// How many buffers came back from gone sessions so far.
    pub(crate) fn given_back(&self) -> u64 {
        lock(&self.state).given_back
    }

    /// How many listed buffers a session that is gone was sent and nothing in this part
    /// holds (they wait for the grace, for the other readers' answers, or for sessions
    /// that cannot answer).
    pub(crate) fn gone_held(&self) -> u64 {
        let s = lock(&self.state);
        let n = (s.entries.values())
            .filter(|e| e.record.some_gone(s.session, &s.present) && !e.record.lent_held())
            .count();
        n as u64
    }

    /// The session number to ask the readers for, if a buffer waits for their word
    /// (a session it was sent to is gone, another has not said it is done), no
    /// question is on its way and the last went [`ASK_EVERY`] ago or more.
    pub(crate) fn to_ask(&self, now: Instant) -> Option<u64> {
        let mut s = lock(&self.state);
        let recent = (s.asked_at).is_some_and(|at| now.saturating_duration_since(at) < ASK_EVERY);
        if s.asking || recent {
            return None;
        }
        let (session, present) = (s.session?, &s.present);
        let waiting = (s.entries.values()).any(|e| {
            let record = &e.record;
            record.some_gone(Some(session), present) && !record.readers_gone(Some(session), present)
        });
        if waiting {
            s.asking = true;
            s.asked_at = Some(now);
        }
        waiting.then_some(session)
    }

    /// The question is over (answered, timed out or not sent).
    pub(crate) fn asked(&self) {
        lock(&self.state).asking = false;
    }

    /// A reader's `answer` to the question asked for the session numbered `asked`.
    pub(crate) fn answered(&self, asked: u64, answer: &Answer) {
        let mut s = lock(&self.state);
        for e in s.entries.values_mut() {
            if let Sent::To {
                session,
                peers,
                sends,
                done,
            } = &mut e.record.sent
            {
                if *session == asked && peers.contains(&answer.reader) && answer.done_with(sends) {
                    done.insert(answer.reader.clone());
                }
            }
        }
    }
}

impl Entry {
    /// Whether nobody but the ledger holds the buffer (or Zenoh's watchdog gave up on
    /// it: then it is left to Zenoh's own collection, as without the ledger).
    fn only_here(&mut self) -> bool {
        if self.record.lent_held() {
            return false;
        }
        if !self.held.is_valid() {
            return true;
        }
        <&mut zshmmut>::try_from(&mut self.held).is_ok()
    }
}

impl Record {
    fn lent_held(&self) -> bool {
        self.lent.as_ref().is_some_and(|l| l.strong_count() > 0)
    }

    /// Whether no output of this part holds the buffer and every session it was sent
    /// to (by the session `now`) is gone (its transport closed and its process ended)
    /// or answered it is done with it, at least one really gone. A buffer sent to no
    /// session at all never is (whoever holds it is in this process, a subscriber of
    /// the part's own session).
    fn gone(&self, now: Option<u64>, present: &BTreeSet<String>) -> bool {
        !self.lent_held() && self.readers_gone(now, present)
    }

    /// [`gone`](Self::gone), whether or not an output of this part still holds it.
    fn readers_gone(&self, now: Option<u64>, present: &BTreeSet<String>) -> bool {
        match &self.sent {
            Sent::To {
                session,
                peers,
                done,
                ..
            } => {
                Some(*session) == now
                    && peers.iter().any(|p| ended(p, present))
                    && peers.iter().all(|p| done.contains(p) || ended(p, present))
            }
            Sent::Left => true,
            Sent::Not | Sent::Unknown => false,
        }
    }
}

impl Record {
    /// Whether a session the buffer was sent to (by the session `now`) is gone.
    fn some_gone(&self, now: Option<u64>, present: &BTreeSet<String>) -> bool {
        match &self.sent {
            Sent::To { session, peers, .. } => {
                Some(*session) == now && peers.iter().any(|p| ended(p, present))
            }
            _ => false,
        }
    }
}

/// Whether the session `peer` is gone: no transport to it, and its process ended.
fn ended(peer: &str, present: &BTreeSet<String>) -> bool {
    !present.contains(peer) && process::gone(peer)
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}
