//! Data-triggered wakeups: an input can carry a notifier that every delivery calls.
//!
//! A thread container registers one [`Notify`] (usually a shared [`Wakeup`]) on the
//! inputs that trigger it. Publishing then costs one atomic load per input when no
//! notifier is registered, and one call when one is.

use std::ptr;
use std::time::{Duration, Instant};

use crate::sync::{AtomicPtr, Ordering};

/// Something to call when new data arrives at an input.
///
/// Called on the publisher's thread, right after the delivery: keep it short and never
/// block in it (set a flag, unpark a thread, notify a condition variable).
pub trait Notify: Send + Sync {
    /// New data arrived.
    fn notify(&self);
}

impl<F: Fn() + Send + Sync> Notify for F {
    fn notify(&self) {
        self()
    }
}

impl std::fmt::Debug for dyn Notify {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Notify")
    }
}

/// A shareable notifier as stored by inputs.
pub type Notifier = std::sync::Arc<dyn Notify>;

/// A wakeup flag a thread can sleep on; register it (cloned into a [`Notifier`]) on the
/// inputs that should wake the thread.
///
/// Notifications are not lost: one that arrives while nobody waits is remembered and
/// makes the next wait return at once. Several notifications before a wait count once.
#[derive(Default)]
pub struct Wakeup {
    pending: std::sync::Mutex<bool>,
    cv: std::sync::Condvar,
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

    fn pending(&self) -> std::sync::MutexGuard<'_, bool> {
        self.pending.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Waits until notified (returns at once if a notification is pending) and clears
    /// the notification.
    pub fn wait(&self) {
        let mut p = self.pending();
        while !*p {
            p = self.cv.wait(p).unwrap_or_else(|e| e.into_inner());
        }
        *p = false;
    }

    /// Clears a pending notification without waiting; true if there was one.
    pub fn take(&self) -> bool {
        std::mem::replace(&mut *self.pending(), false)
    }

    /// Like [`Self::wait`] with a time limit; true if notified, false on timeout.
    pub fn wait_timeout(&self, timeout: Duration) -> bool {
        let deadline = Instant::now() + timeout;
        let mut p = self.pending();
        while !*p {
            let now = Instant::now();
            if now >= deadline {
                return false;
            }
            p = match self.cv.wait_timeout(p, deadline - now) {
                Ok((g, _)) => g,
                Err(e) => e.into_inner().0,
            };
        }
        *p = false;
        true
    }
}

impl Notify for Wakeup {
    fn notify(&self) {
        let mut p = self.pending();
        if !*p {
            *p = true;
            self.cv.notify_all();
        }
    }
}

/// A value set at most once and read without locking (one Acquire load).
pub(crate) struct SetOnce<V> {
    ptr: AtomicPtr<V>,
}

impl<V> SetOnce<V> {
    pub(crate) fn new() -> Self {
        SetOnce {
            ptr: AtomicPtr::new(ptr::null_mut()),
        }
    }

    /// Sets the value; gives it back if one was already set.
    pub(crate) fn set(&self, value: V) -> Result<(), V> {
        let new = Box::into_raw(Box::new(value));
        match self
            .ptr
            .compare_exchange(ptr::null_mut(), new, Ordering::AcqRel, Ordering::Acquire)
        {
            Ok(_) => Ok(()),
            // SAFETY: `new` was not published; we still own it.
            Err(_) => Err(*unsafe { Box::from_raw(new) }),
        }
    }

    pub(crate) fn get(&self) -> Option<&V> {
        let p = self.ptr.load(Ordering::Acquire);
        // SAFETY: once set, the box lives until `self` is dropped and is never mutated.
        unsafe { p.as_ref() }
    }
}

impl<V> Drop for SetOnce<V> {
    fn drop(&mut self) {
        let p = self.ptr.load(Ordering::Acquire);
        if !p.is_null() {
            // SAFETY: set from Box::into_raw and owned by us.
            drop(unsafe { Box::from_raw(p) });
        }
    }
}
