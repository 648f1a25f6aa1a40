//! Time as a thread container sees it: the real monotonic clock, or a manual clock that
//! tests advance by hand so that timing logic is tested without wall-clock assertions.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// A monotonic clock measured from an arbitrary origin.
pub trait Clock: Send + Sync + 'static {
    /// Time since the clock's origin.
    fn now(&self) -> Duration;
    /// Sleeps until `deadline` (returns at once if it has passed).
    fn sleep_until(&self, deadline: Duration);
    /// Like [`sleep_until`](Self::sleep_until), but returns early once `stop` is set
    /// and the sleeping thread is unparked (a stop must not wait for a long period).
    fn sleep_until_or_stop(&self, deadline: Duration, stop: &AtomicBool) {
        let _ = stop;
        self.sleep_until(deadline);
    }
}

/// The operating system's monotonic clock.
#[derive(Debug, Clone)]
pub struct SystemClock {
    origin: Instant,
}

impl Default for SystemClock {
    fn default() -> Self {
        SystemClock {
            origin: Instant::now(),
        }
    }
}

impl Clock for SystemClock {
    fn now(&self) -> Duration {
        self.origin.elapsed()
    }

    fn sleep_until(&self, deadline: Duration) {
        let now = self.now();
        if deadline > now {
            std::thread::sleep(deadline - now);
        }
    }

    fn sleep_until_or_stop(&self, deadline: Duration, stop: &AtomicBool) {
        // Parking may wake early (spuriously, or by an unpark meant for the stop):
        // sleep again until the deadline unless the stop is what woke us.
        loop {
            let now = self.now();
            if deadline <= now || stop.load(Ordering::Relaxed) {
                return;
            }
            std::thread::park_timeout(deadline - now);
        }
    }
}

/// A clock that moves only when told to: [`ManualClock::advance`], or sleeping (which
/// jumps to the deadline). Cloned handles share one time.
#[derive(Debug, Clone, Default)]
pub struct ManualClock {
    nanos: Arc<AtomicU64>,
}

impl ManualClock {
    /// A clock at time zero.
    pub fn new() -> Self {
        Self::default()
    }

    /// Moves time forward (what a step "takes" in a test).
    pub fn advance(&self, by: Duration) {
        self.nanos
            .fetch_add(by.as_nanos().min(u64::MAX as u128) as u64, Ordering::SeqCst);
    }
}

impl Clock for ManualClock {
    fn now(&self) -> Duration {
        Duration::from_nanos(self.nanos.load(Ordering::SeqCst))
    }

    fn sleep_until(&self, deadline: Duration) {
        let target = deadline.as_nanos().min(u64::MAX as u128) as u64;
        self.nanos.fetch_max(target, Ordering::SeqCst);
    }
}
