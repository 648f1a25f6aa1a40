//! The one place that names the synchronisation primitives.
//!
//! Every atomic, `Arc`, `Mutex` and `Condvar` of the port core and of services comes
//! from here, so the same code runs on `std` in normal builds and on [loom]'s
//! model-checked versions when compiled with `RUSTFLAGS="--cfg loom"` (see
//! `tests/loom_ports.rs` and `tests/loom_services.rs`). Only the types the core needs
//! are re-exported; anything else would escape the model checker.
//!
//! [loom]: https://docs.rs/loom

#[cfg(not(loom))]
pub use std::sync::{
    atomic::{fence, AtomicBool, AtomicPtr, AtomicU64, AtomicUsize, Ordering},
    Arc, Condvar, Mutex, MutexGuard,
};

#[cfg(loom)]
pub use loom::sync::{
    atomic::{fence, AtomicBool, AtomicPtr, AtomicU64, AtomicUsize, Ordering},
    Arc, Condvar, Mutex, MutexGuard,
};

/// Loom's cell: every access is checked for a race with the other threads' accesses.
#[cfg(loom)]
pub use loom::cell::UnsafeCell;

/// `std`'s cell with loom's access API (`with`, `with_mut`), so the code that touches a
/// cell reads the same in both builds.
#[cfg(not(loom))]
pub struct UnsafeCell<T>(std::cell::UnsafeCell<T>);

#[cfg(not(loom))]
impl<T> UnsafeCell<T> {
    pub fn new(value: T) -> Self {
        UnsafeCell(std::cell::UnsafeCell::new(value))
    }

    /// Calls `f` with a pointer for reading.
    #[inline(always)]
    pub fn with<R>(&self, f: impl FnOnce(*const T) -> R) -> R {
        f(self.0.get())
    }

    /// Calls `f` with a pointer for writing.
    #[inline(always)]
    pub fn with_mut<R>(&self, f: impl FnOnce(*mut T) -> R) -> R {
        f(self.0.get())
    }
}

/// A busy-wait hint. Under loom this yields to the scheduler, which is what lets the
/// model checker explore a retry loop without exploring it forever.
#[inline]
pub fn spin_loop() {
    #[cfg(not(loom))]
    std::hint::spin_loop();
    #[cfg(loom)]
    loom::hint::spin_loop();
}

/// Locks a mutex, ignoring poisoning: every critical section of the port core leaves its
/// data consistent at each step, so a panic elsewhere must not make ports unusable.
#[inline]
pub fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}
