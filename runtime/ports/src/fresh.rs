//! How fresh the values of a link are, for the inputs it feeds: a reader never takes
//! silence for data. The receiving end of a link notes when each value arrives and
//! whether the writer's part is gone (the network says so); an input fed by the link
//! shows it through `ferroc_module::In::age` and
//! `In::is_stale`.

use crate::time::Timestamp;
use std::sync::atomic::{AtomicBool, AtomicI64, AtomicU64, Ordering};
use std::sync::{Arc, OnceLock};
use std::time::Duration;

/// The freshness of the link feeding an input, set when a link is connected to it.
pub type Source = OnceLock<Arc<Freshness>>;

/// A value on its way into the port (see [`Freshness::arriving`]).
#[derive(Clone, Copy, Debug)]
pub struct Arrival {
    before: i64,
    now: i64,
}

/// The freshness of one link's values.
#[derive(Debug)]
pub struct Freshness {
    /// Model time (ns) of the latest value; `i64::MIN` before the first.
    last: AtomicI64,
    /// The writer's part is gone.
    gone: AtomicBool,
    /// `deadline=`: the longest silence accepted.
    deadline: Option<Duration>,
    /// Gaps longer than the deadline so far.
    missed: AtomicU64,
}

impl Default for Freshness {
    fn default() -> Self {
        Freshness::with_deadline(None)
    }
}

impl Freshness {
    /// The freshness of a link with `deadline=` (or none).
    pub fn with_deadline(deadline: Option<Duration>) -> Self {
        Freshness {
            last: AtomicI64::new(i64::MIN),
            gone: AtomicBool::new(false),
            deadline,
            missed: AtomicU64::new(0),
        }
    }

    /// A value arrived now; the gap since the previous one when it exceeded the
    /// deadline.
    #[cfg(test)]
    #[inline]
    pub fn arrived(&self, now: Timestamp) -> Option<Duration> {
        self.arrived_after(self.arriving(now))
    }

    /// A value is arriving now: its time is noted before it is published (so that a
    /// reader it wakes sees it), to be confirmed with [`arrived_after`](Self::arrived_after)
    /// or taken back with [`not_arrived`](Self::not_arrived) if it does not decode.
    #[inline]
    pub fn arriving(&self, now: Timestamp) -> Arrival {
        let before = self.last.swap(now.nanos, Ordering::Relaxed);
        Arrival {
            before,
            now: now.nanos,
        }
    }

    /// The value of `arrival` was published: the gap since the previous one when it
    /// exceeded the deadline.
    #[inline]
    pub fn arrived_after(&self, arrival: Arrival) -> Option<Duration> {
        let deadline = self.deadline?;
        if arrival.before == i64::MIN {
            return None;
        }
        let gap = Duration::from_nanos(
            u64::try_from(arrival.now.saturating_sub(arrival.before)).unwrap_or(0),
        );
        (gap > deadline).then(|| {
            self.missed.fetch_add(1, Ordering::Relaxed);
            gap
        })
    }

    /// The value of `arrival` did not decode: the previous arrival time stands (unless
    /// another value arrived meanwhile).
    #[inline]
    pub fn not_arrived(&self, arrival: Arrival) {
        let _ = self.last.compare_exchange(
            arrival.now,
            arrival.before,
            Ordering::Relaxed,
            Ordering::Relaxed,
        );
    }

    /// Reports a missed deadline: the first one, then every 100th (a link that keeps
    /// missing it would flood the output).
    pub fn report_missed(&self, describe: &str, gap: Duration) {
        let n = self.missed.load(Ordering::Relaxed);
        if n == 1 || n % 100 == 0 {
            let deadline = self.deadline.unwrap_or_default();
            crate::console::note(&format!(
                "warning: {describe}: deadline {} ms missed: {} ms between values ({n} time(s) so far)",
                deadline.as_millis(),
                gap.as_millis()
            ));
        }
    }

    /// How many gaps exceeded the deadline.
    #[cfg(test)]
    #[inline]
    pub fn missed(&self) -> u64 {
        self.missed.load(Ordering::Relaxed)
    }

    /// The writer's part is gone (`true`) or back.
    #[inline]
    pub fn set_gone(&self, gone: bool) {
        self.gone.store(gone, Ordering::Relaxed);
    }

    /// Whether the writer's part is gone (for inspection).
    #[inline]
    pub fn is_gone(&self) -> bool {
        self.gone.load(Ordering::Relaxed)
    }

    /// How long ago the latest value arrived; `None` before the first.
    #[inline]
    pub fn age(&self, now: Timestamp) -> Option<Duration> {
        let last = self.last.load(Ordering::Relaxed);
        (last != i64::MIN).then(|| {
            Duration::from_nanos(u64::try_from(now.nanos.saturating_sub(last)).unwrap_or(0))
        })
    }

    /// No value arrived yet, the writer's part is gone, or the latest value is older
    /// than the deadline.
    #[inline]
    pub fn is_stale(&self, now: Timestamp) -> bool {
        let overdue = self
            .deadline
            .is_some_and(|d| self.age(now).is_some_and(|age| age > d));
        self.gone.load(Ordering::Relaxed)
            || self.last.load(Ordering::Relaxed) == i64::MIN
            || overdue
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_link_is_stale_until_a_value_arrives_and_while_its_writer_is_gone() {
        let f = Freshness::default();
        let at = |ms: i64| Timestamp {
            nanos: ms * 1_000_000,
        };
        assert!(f.is_stale(at(5)) && f.age(at(5)).is_none(), "nothing yet");
        assert_eq!(f.arrived(at(10)), None);
        assert!(!f.is_stale(at(10_000)), "no deadline: old is not stale");
        assert_eq!(f.age(at(35)), Some(Duration::from_millis(25)));
        f.set_gone(true);
        assert!(f.is_stale(at(40)), "the writer's part is gone");
        assert_eq!(
            f.age(at(40)),
            Some(Duration::from_millis(30)),
            "age goes on"
        );
        f.set_gone(false);
        assert!(!f.is_stale(at(40)), "back");
    }

    #[test]
    fn a_deadline_makes_silence_stale_and_counts_the_gaps_that_exceed_it() {
        let f = Freshness::with_deadline(Some(Duration::from_millis(200)));
        let at = |ms: i64| Timestamp {
            nanos: ms * 1_000_000,
        };
        assert_eq!(f.arrived(at(0)), None, "the first value has no gap");
        assert!(!f.is_stale(at(200)), "exactly the deadline is in time");
        assert!(f.is_stale(at(201)), "past the deadline");
        assert_eq!(f.arrived(at(150)), None, "in time");
        assert_eq!(f.arrived(at(500)), Some(Duration::from_millis(350)));
        assert!(!f.is_stale(at(600)));
        assert_eq!(f.missed(), 1);
    }

    #[test]
    fn a_value_that_does_not_decode_leaves_the_arrival_before_it() {
        let f = Freshness::default();
        let at = |ms: i64| Timestamp {
            nanos: ms * 1_000_000,
        };
        let first = f.arriving(at(10));
        assert!(!f.is_stale(at(10)), "noted before the value is published");
        f.not_arrived(first);
        assert!(f.is_stale(at(11)), "it did not decode: still nothing");
        f.arrived(at(20));
        f.not_arrived(f.arriving(at(30)));
        assert_eq!(f.age(at(40)), Some(Duration::from_millis(20)));
    }
}
