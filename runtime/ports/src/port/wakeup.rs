//! [`Wakeup`]: the flag a data-triggered container sleeps on, and the ways it can wait
//! for it ([`WaitMode`]); with `wait="inline"` nobody sleeps on it: a notification runs
//! the container's cycle in the notifying thread ([`Wakeup::run_inline`]).
//!
//! The flag is an atomic so that a spinning waiter sees a notification with one load
//! and a notifier pays no lock and no system call while nobody sleeps. Sleepers
//! register in `sleeping` before they look at the flag a last time; a notifier sets the
//! flag before it looks at `sleeping`. Both are sequentially consistent, so at least one
//! side sees the other (the notifier wakes the sleeper, or the sleeper sees the flag);
//! the notifier takes the mutex before it signals, and the sleeper holds it from its last
//! look until the condition variable releases it, so the signal (given right after the
//! notifier's unlock) cannot fall between the two. `tests/loom_wakeup.rs` checks this under every interleaving.

use std::sync::atomic::AtomicBool as StdAtomicBool;
use std::time::{Duration, Instant};

use super::notify::{Notifier, SetOnce};
use crate::sync::{self, AtomicBool, AtomicUsize, Condvar, Mutex, Ordering};

/// How a data-triggered container waits for data (`wait=` on `<thread>`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum WaitMode {
    /// Sleep in the kernel until notified: no CPU while idle, a thread wakeup of
    /// latency (tens of microseconds on a loaded machine).
    #[default]
    Park,
    /// Poll the flag without ever sleeping: the lowest latency, and a whole core
    /// (meant for a core reserved to the container).
    Spin,
    /// Poll as `Spin` does for [`ADAPTIVE_SPIN`], then sleep as `Park` does: low
    /// latency when data comes often, no CPU when it stops.
    Adaptive,
    /// No thread waits: the cycle runs in the thread that delivers the trigger value
    /// (a link's network callback, an in-process writer), one at a time
    /// ([`InlineGate`](super::InlineGate)). No wakeup latency and no CPU while idle;
    /// the step holds up the delivering thread, so it must be short and never block
    /// (the compiler's S108 refuses what it can see).
    Inline,
}

impl WaitMode {
    /// The model's spelling (`park`, `spin`, `adaptive`).
    pub fn as_str(self) -> &'static str {
        match self {
            WaitMode::Park => "park",
            WaitMode::Spin => "spin",
            WaitMode::Adaptive => "adaptive",
            WaitMode::Inline => "inline",
        }
    }

    /// Parses the model's spelling.
    pub fn parse(text: &str) -> Option<Self> {
        match text {
            "park" => Some(WaitMode::Park),
            "spin" => Some(WaitMode::Spin),
            "adaptive" => Some(WaitMode::Adaptive),
            "inline" => Some(WaitMode::Inline),
            _ => None,
        }
    }
}

/// How long `wait="adaptive"` polls before it sleeps.
pub const ADAPTIVE_SPIN: Duration = Duration::from_micros(200);

/// A wakeup flag a thread can wait on; register it (cloned into a
/// [`Notifier`](super::Notifier)) on the inputs that should wake the thread.
///
/// Notifications are not lost: one that arrives while nobody waits is remembered and
/// makes the next wait return at once. Several notifications before a wait count once.
pub struct Wakeup {
    pending: AtomicBool,
    /// Waiters between registering and leaving the condition variable.
    sleeping: AtomicUsize,
    lock: Mutex<()>,
    cv: Condvar,
    /// `wait="inline"`: what a notification calls instead of setting the flag.
    inline: SetOnce<Notifier>,
}

impl Default for Wakeup {
    fn default() -> Self {
        Wakeup {
            pending: AtomicBool::new(false),
            sleeping: AtomicUsize::new(0),
            lock: Mutex::new(()),
            cv: Condvar::new(),
            inline: SetOnce::new(),
        }
    }
}

impl std::fmt::Debug for Wakeup {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Wakeup").finish_non_exhaustive()
    }
}

impl Wakeup {
    /// A new wakeup, not pending.
    pub fn new() -> std::sync::Arc<Self> {
        std::sync::Arc::new(Self::default())
    }

    /// From now on every notification calls `runner` on the notifying thread instead of
    /// setting the flag (`wait="inline"`); a notification already pending stays so
    /// (see [`Self::take`]). Gives `runner` back if one was set before.
    pub fn run_inline(&self, runner: Notifier) -> Result<(), Notifier> {
        self.inline.set(runner)
    }

    /// Clears a pending notification without waiting; true if there was one.
    pub fn take(&self) -> bool {
        // The plain load keeps a spinning waiter from writing the cache line the
        // notifier writes.
        self.pending.load(Ordering::Relaxed) && self.pending.swap(false, Ordering::SeqCst)
    }

    /// Waits until notified (returns at once if a notification is pending) and clears
    /// the notification.
    pub fn wait(&self) {
        self.sleep(None);
    }

    /// Like [`Self::wait`] with a time limit; true if notified, false on timeout.
    pub fn wait_timeout(&self, timeout: Duration) -> bool {
        self.take() || self.sleep(Some(Instant::now() + timeout))
    }

    /// Waits as `mode` says until notified (true), `stop` is set or `timeout` passed
    /// (false). Spinning looks at `stop` on every turn; a parked waiter sees it when it
    /// is notified (a nudge) or when the time is up.
    pub fn wait_in(&self, mode: WaitMode, stop: &StdAtomicBool, timeout: Duration) -> bool {
        let stopped = || stop.load(std::sync::atomic::Ordering::Relaxed);
        match mode {
            // A container told to wait inline but run on a thread of its own (run
            // directly, not spawned) waits as `Park` does.
            WaitMode::Park | WaitMode::Inline => self.wait_timeout(timeout),
            WaitMode::Spin => loop {
                if self.take() {
                    return true;
                }
                if stopped() {
                    return false;
                }
                sync::spin_loop();
            },
            WaitMode::Adaptive => {
                // One pause per look, as `Spin`: no backoff. A backoff that doubles
                // its pauses (crossbeam's `Backoff::spin`, up to 64 a look) cost ~0.9 us
                // of p50 in b4 here, for nothing: the waiter only reads the flag, so
                // there is no contention to back off from. No yield either: it hands a
                // loaded core to another process for a time slice (b4: ~380 us p50).
                let started = Instant::now();
                let mut looks = 0u32;
                loop {
                    if self.take() {
                        return true;
                    }
                    if stopped() {
                        return false;
                    }
                    looks = looks.wrapping_add(1);
                    // The clock every 64 looks: a read costs more than a look.
                    if looks % 64 == 0 && started.elapsed() >= ADAPTIVE_SPIN {
                        return self.wait_timeout(timeout.saturating_sub(ADAPTIVE_SPIN));
                    }
                    sync::spin_loop();
                }
            }
        }
    }

    /// Sleeps on the condition variable until notified or `deadline`.
    fn sleep(&self, deadline: Option<Instant>) -> bool {
        let mut guard = sync::lock(&self.lock);
        self.sleeping.fetch_add(1, Ordering::SeqCst);
        let notified = loop {
            if self.pending.swap(false, Ordering::SeqCst) {
                break true;
            }
            guard = match deadline {
                None => self.cv.wait(guard).unwrap_or_else(|e| e.into_inner()),
                Some(deadline) => {
                    let now = Instant::now();
                    if now >= deadline {
                        break false;
                    }
                    match self.cv.wait_timeout(guard, deadline - now) {
                        Ok((g, _)) => g,
                        Err(e) => e.into_inner().0,
                    }
                }
            };
        };
        self.sleeping.fetch_sub(1, Ordering::SeqCst);
        drop(guard);
        notified
    }
}

impl super::Notify for Wakeup {
    fn notify(&self) {
        if let Some(runner) = self.inline.get() {
            runner.notify();
            return;
        }
        if !self.pending.swap(true, Ordering::SeqCst) && self.sleeping.load(Ordering::SeqCst) > 0 {
            // Taking the lock orders the signal after the sleeper's last look (it holds
            // the lock until the condition variable releases it). Signalling after the
            // unlock spares the woken thread from blocking on the mutex at once.
            drop(sync::lock(&self.lock));
            self.cv.notify_all();
        }
    }
}
