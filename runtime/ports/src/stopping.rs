//! The stop request of the application, as seen from inside a running step.
//!
//! A step can wait inside the port core: a write into a full `on-full="block"` queue
//! waits for room. When the consumer runs in the same thread container (or has
//! stopped), that room never comes, and a stop request (Ctrl-C, SIGTERM, `--for`) must
//! still end the run. Every thread that runs containers registers the application's
//! stop flag here; the waits of the port core ask [`requested`] and give up (dropping
//! the value) once it is set.

use std::cell::RefCell;
use std::sync::atomic::AtomicBool;
#[cfg(not(loom))]
use std::sync::atomic::Ordering;
use std::sync::Arc;

thread_local! {
    static STOP: RefCell<Option<Arc<AtomicBool>>> = const { RefCell::new(None) };
}

/// Makes `stop` the flag that waits on this thread watch.
pub fn watch(stop: Arc<AtomicBool>) {
    STOP.with(|s| *s.borrow_mut() = Some(stop));
}

/// Makes `stop` the flag that waits on this thread watch for a while (an inline
/// container's cycle run by a thread that delivered its value); gives back the flag
/// watched before, for the caller to put back.
pub fn swap(stop: Option<Arc<AtomicBool>>) -> Option<Arc<AtomicBool>> {
    STOP.with(|s| std::mem::replace(&mut *s.borrow_mut(), stop))
}

/// Whether the application running on this thread has been asked to stop. False on
/// threads that run no container (and under loom, whose threads share one OS thread).
#[inline]
pub fn requested() -> bool {
    #[cfg(loom)]
    return false;
    #[cfg(not(loom))]
    STOP.with(|s| {
        s.borrow()
            .as_ref()
            .is_some_and(|f| f.load(Ordering::Relaxed))
    })
}
