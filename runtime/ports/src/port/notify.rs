//! Data-triggered wakeups: an input can carry a notifier that every delivery calls.
//!
//! A thread container registers one [`Notify`] (usually a shared [`Wakeup`]) on the
//! inputs that trigger it. Publishing then costs one atomic load per input when no
//! notifier is registered, and one call when one is.

use std::ptr;

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

pub use super::wakeup::{WaitMode, Wakeup};

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
