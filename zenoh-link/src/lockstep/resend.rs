//! Sending an instant again that was lost on the way.
//!
//! Zenoh sends reliably over one link, but when a link closes (its lease passed on a
//! loaded machine, its connection broke) the messages still queued on it are gone, and
//! the session goes on over the other link between the two programs or a new one: no
//! error, no withdrawn token, only a gap. So every instant a part sends to another has
//! a number (`seq`, counted from 0 for each sender and receiver), the sender keeps its
//! latest instants ([`Kept`]) and answers a `get` on the same key with `from=SEQ` with
//! those from that number on, and the receiver ([`Inbox`]) takes them in order, asks
//! for what is missing and drops what it has already. An instant no longer kept is an
//! error, never a gap.

use super::Instant;
use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::sync::Mutex;
use std::time::{Duration, Instant as Clock};
use zenoh::bytes::ZBytes;

/// How many of its latest instants a part keeps for each part it sends to.
pub(crate) const KEEP_INSTANTS: usize = 256;

/// How many bytes of them at most (the newest instant is always kept).
pub(crate) const KEEP_BYTES: usize = 32 << 20;

/// How long a receiver waits for the missing instants it asked for before asking again.
const ASK_AGAIN: Duration = Duration::from_millis(200);

/// How long a receiver waits for the next instant of a part, hearing nothing from it,
/// before asking whether it was lost (the last one before a pause has no successor
/// that would show the gap).
const QUIET: Duration = Duration::from_secs(1);

/// The latest instants a part sent to another, by number.
#[derive(Default)]
pub(crate) struct Kept {
    /// The number of the first kept instant.
    first: u64,
    items: VecDeque<ZBytes>,
    bytes: usize,
}

impl Kept {
    /// Keeps the next instant's message; its number.
    pub(crate) fn push(&mut self, payload: ZBytes) -> u64 {
        let seq = self.first + self.items.len() as u64;
        self.bytes += payload.len();
        self.items.push_back(payload);
        while self.items.len() > KEEP_INSTANTS || (self.bytes > KEEP_BYTES && self.items.len() > 1)
        {
            if let Some(old) = self.items.pop_front() {
                self.bytes -= old.len();
                self.first += 1;
            }
        }
        seq
    }

    /// The number the next instant gets.
    pub(crate) fn next_seq(&self) -> u64 {
        self.first + self.items.len() as u64
    }

    /// The messages from the number `from` on (none yet: empty), or why they are gone.
    pub(crate) fn from(&self, from: u64) -> Result<Vec<ZBytes>, String> {
        if from < self.first {
            return Err(format!(
                "the instant #{from} is no longer kept (the oldest kept is #{}, at most \
                 {KEEP_INSTANTS} instants or {} MiB)",
                self.first,
                KEEP_BYTES >> 20
            ));
        }
        let skip = usize::try_from(from - self.first).unwrap_or(usize::MAX);
        Ok(self.items.iter().skip(skip).cloned().collect())
    }
}

/// `from=SEQ` in a query's parameters.
pub(crate) fn asked_from(parameters: &str) -> Option<u64> {
    (parameters.split(';'))
        .find_map(|p| p.strip_prefix("from="))
        .and_then(|n| n.parse().ok())
}

/// What a receiver has of one sender's instants.
pub(crate) struct Inbox {
    /// The number of the next instant to take.
    next: u64,
    /// Instants that came before one they follow.
    early: BTreeMap<u64, Instant>,
    /// Instants in order, to be taken by the instant they belong to.
    pub(crate) ready: VecDeque<Instant>,
    /// When the last instant came in order, or the latest wait began.
    heard: Clock,
    /// When this receiver last asked for instants again.
    asked: Option<Clock>,
    /// How many instants came only when asked for again.
    pub(crate) resent: u64,
}

impl Default for Inbox {
    fn default() -> Self {
        Inbox {
            next: 0,
            early: BTreeMap::new(),
            ready: VecDeque::new(),
            heard: Clock::now(),
            asked: None,
            resent: 0,
        }
    }
}

impl Inbox {
    /// Takes the instant `seq` (sent again when `again`): in order it is ready, with
    /// those that came early after it; one already had is dropped.
    pub(crate) fn arrive(&mut self, seq: u64, instant: Instant, again: bool) {
        if seq < self.next || self.early.contains_key(&seq) {
            return;
        }
        self.resent += u64::from(again);
        self.early.insert(seq, instant);
        while let Some(instant) = self.early.remove(&self.next) {
            self.ready.push_back(instant);
            self.next += 1;
            self.heard = Clock::now();
        }
    }

    /// The number to ask the sender for instants from, if it is time to: at once when
    /// later instants show a gap (then again every [`ASK_AGAIN`]), and after
    /// [`QUIET`] without an instant once one came (before its first instant a sender
    /// waits until this part listens, so nothing of it can be lost yet; a first one
    /// lost later shows as a gap when the next comes). Called only while this sender is
    /// waited for and nothing that arrived is still unread.
    pub(crate) fn ask(&mut self, now: Clock) -> Option<u64> {
        let since_asked = self.asked.map(|t| now.saturating_duration_since(t));
        let due = match self.early.is_empty() {
            false => since_asked.is_none_or(|d| d >= ASK_AGAIN),
            true => {
                self.next > 0
                    && now.saturating_duration_since(self.heard) >= QUIET
                    && since_asked.is_none_or(|d| d >= QUIET)
            }
        };
        if due {
            self.asked = Some(now);
        }
        due.then_some(self.next)
    }

    /// Whether the instant `from` asked for is still missing (an answer that it is no
    /// longer kept matters only then).
    pub(crate) fn lacks(&self, from: u64) -> bool {
        self.next <= from
    }

    /// A wait for this sender begins now: its silence counts from here (a receiver
    /// busy with its own work for a while heard nothing, but nothing was missing).
    pub(crate) fn wait_begins(&mut self, now: Clock) {
        self.heard = self.heard.max(now);
    }
}

/// Messages a test makes "lost on the way" (by key and number): kept, never put.
static LOSE: Mutex<BTreeSet<(String, u64)>> = Mutex::new(BTreeSet::new());

/// For tests: the instant `seq` on the lockstep key `key` (`ferroc/APP/lockstep/FROM/TO`)
/// is kept by its sender but never put, as if the link it went on had closed.
#[doc(hidden)]
pub fn lose_on_the_way(key: &str, seq: u64) {
    LOSE.lock()
        .unwrap_or_else(|e| e.into_inner())
        .insert((key.to_owned(), seq));
}

/// Whether the instant `seq` on `key` is to be lost ([`lose_on_the_way`]).
pub(crate) fn to_lose(key: &str, seq: u64) -> bool {
    let lose = LOSE.lock().unwrap_or_else(|e| e.into_inner());
    !lose.is_empty() && lose.contains(&(key.to_owned(), seq))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn instant(nanos: u64) -> Instant {
        Instant {
            seq: 0,
            nanos,
            frames: vec![],
        }
    }

    fn nanos(inbox: &Inbox) -> Vec<u64> {
        inbox.ready.iter().map(|i| i.nanos).collect()
    }

    #[test]
    fn a_gap_is_asked_for_at_once_and_filled_in_order() {
        let mut inbox = Inbox::default();
        inbox.arrive(0, instant(0), false);
        inbox.arrive(2, instant(20), false);
        assert_eq!(nanos(&inbox), [0], "20 waits for 10");
        let now = Clock::now();
        assert_eq!(inbox.ask(now), Some(1));
        assert_eq!(inbox.ask(now), None, "not again at once");
        assert_eq!(inbox.ask(now + ASK_AGAIN), Some(1), "again later");
        inbox.arrive(1, instant(10), true);
        inbox.arrive(2, instant(20), true);
        assert_eq!(nanos(&inbox), [0, 10, 20]);
        assert_eq!(inbox.resent, 1, "the copy of 20 is dropped");
        assert!(!inbox.lacks(1) && inbox.lacks(3));
    }

    #[test]
    fn in_order_nothing_is_asked_until_the_sender_is_quiet() {
        let mut inbox = Inbox::default();
        let start = Clock::now();
        assert_eq!(
            inbox.ask(start + QUIET),
            None,
            "nothing came yet: nothing lost"
        );
        inbox.arrive(0, instant(0), false);
        inbox.arrive(1, instant(10), false);
        let now = Clock::now();
        assert_eq!(inbox.ask(now), None);
        assert_eq!(inbox.ask(now + QUIET), Some(2));
        assert_eq!(
            inbox.ask(now + QUIET + ASK_AGAIN),
            None,
            "quietly: every QUIET"
        );
    }

    #[test]
    fn the_sender_keeps_its_latest_instants_and_says_when_one_is_gone() {
        let mut kept = Kept::default();
        assert_eq!(kept.from(0).unwrap().len(), 0, "nothing sent yet");
        for n in 0..KEEP_INSTANTS as u64 + 10 {
            assert_eq!(kept.push(ZBytes::from(n.to_le_bytes().to_vec())), n);
        }
        assert_eq!(kept.next_seq(), KEEP_INSTANTS as u64 + 10);
        let tail = kept.from(KEEP_INSTANTS as u64 + 8).unwrap();
        assert_eq!(tail.len(), 2);
        let err = kept.from(3).unwrap_err();
        assert!(err.contains("#3") && err.contains("#10"), "{err}");
    }

    #[test]
    fn a_large_instant_pushes_out_the_old_ones_but_stays() {
        let mut kept = Kept::default();
        kept.push(ZBytes::from(vec![0u8; 16]));
        kept.push(ZBytes::from(vec![0u8; KEEP_BYTES + 1]));
        assert!(kept.from(0).is_err());
        assert_eq!(kept.from(1).unwrap().len(), 1);
    }

    #[test]
    fn the_number_asked_for_is_read_from_the_parameters() {
        assert_eq!(asked_from("from=12"), Some(12));
        assert_eq!(asked_from("x=1;from=3"), Some(3));
        assert_eq!(asked_from("from=-1"), None);
        assert_eq!(asked_from(""), None);
    }
}
