//! How fresh the values of a link are, for the inputs it feeds: a reader never takes
//! silence for data. The receiving end of a link notes when each value arrives and
//! whether the writer's part is gone (the network says so); an input fed by the link
//! shows it through [`In::age`](crate::module::In::age) and
//! [`In::is_stale`](crate::module::In::is_stale).

use crate::module::Timestamp;
use std::sync::atomic::{AtomicBool, AtomicI64, Ordering};
use std::sync::{Arc, OnceLock};
use std::time::Duration;

/// The freshness of the link feeding an input, set when a link is connected to it.
pub(crate) type Source = OnceLock<Arc<Freshness>>;

/// The freshness of one link's values.
#[derive(Debug)]
pub(crate) struct Freshness {
    /// Model time (ns) of the latest value; `i64::MIN` before the first.
    last: AtomicI64,
    /// The writer's part is gone.
    gone: AtomicBool,
}

impl Default for Freshness {
    fn default() -> Self {
        Freshness {
            last: AtomicI64::new(i64::MIN),
            gone: AtomicBool::new(false),
        }
    }
}

impl Freshness {
    /// A value arrived now.
    pub(crate) fn arrived(&self, now: Timestamp) {
        self.last.store(now.nanos, Ordering::Relaxed);
    }

    /// The writer's part is gone (`true`) or back.
    pub(crate) fn set_gone(&self, gone: bool) {
        self.gone.store(gone, Ordering::Relaxed);
    }

    /// How long ago the latest value arrived; `None` before the first.
    pub(crate) fn age(&self, now: Timestamp) -> Option<Duration> {
        let last = self.last.load(Ordering::Relaxed);
        (last != i64::MIN).then(|| {
            Duration::from_nanos(u64::try_from(now.nanos.saturating_sub(last)).unwrap_or(0))
        })
    }

    /// No value arrived yet, or the writer's part is gone.
    pub(crate) fn is_stale(&self) -> bool {
        self.gone.load(Ordering::Relaxed) || self.last.load(Ordering::Relaxed) == i64::MIN
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
        assert!(f.is_stale() && f.age(at(5)).is_none(), "nothing yet");
        f.arrived(at(10));
        assert!(!f.is_stale());
        assert_eq!(f.age(at(35)), Some(Duration::from_millis(25)));
        f.set_gone(true);
        assert!(f.is_stale(), "the writer's part is gone");
        assert_eq!(
            f.age(at(40)),
            Some(Duration::from_millis(30)),
            "age goes on"
        );
        f.set_gone(false);
        assert!(!f.is_stale(), "back");
    }
}
