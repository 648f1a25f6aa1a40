//! Model-checked tests of [`Wakeup`], the flag data-triggered containers wait on: under
//! every interleaving (up to loom's preemption bound) a notification is never lost,
//! whether the waiter parks on the condition variable or spins on the flag.
//!
//! Run: `RUSTFLAGS="--cfg loom" cargo test -p ferroc-runtime --release --test loom_wakeup`
#![cfg(loom)]

use std::sync::atomic::AtomicBool;
use std::time::Duration;

use ferroc_ports::port::{Notify, WaitMode, Wakeup};
use loom::thread;

/// A parked waiter returns after one notification from another thread, however the
/// notifier's flag store and sleeper check interleave with the waiter's registration.
#[test]
fn a_parked_waiter_is_woken() {
    loom::model(|| {
        let w = Wakeup::new();
        let n = std::sync::Arc::clone(&w);
        let t = thread::spawn(move || n.notify());
        w.wait();
        assert!(!w.take(), "the notification was consumed by the wait");
        t.join().unwrap();
    });
}

/// Two notifiers and a waiter that waits twice: the second wait returns only if a
/// notification came after the first one ended, never hangs otherwise (loom reports a
/// deadlock when every thread is blocked).
#[test]
fn notifications_after_a_wait_wake_the_next_wait() {
    loom::model(|| {
        let w = Wakeup::new();
        let a = std::sync::Arc::clone(&w);
        let t = thread::spawn(move || {
            a.notify();
        });
        w.wait();
        t.join().unwrap();
        let b = std::sync::Arc::clone(&w);
        let t = thread::spawn(move || b.notify());
        w.wait();
        t.join().unwrap();
    });
}

/// A spinning waiter sees the notification on the flag alone (it never takes the lock).
#[test]
fn a_spinning_waiter_sees_the_flag() {
    loom::model(|| {
        let w = Wakeup::new();
        let n = std::sync::Arc::clone(&w);
        let t = thread::spawn(move || n.notify());
        let stop = AtomicBool::new(false);
        assert!(w.wait_in(WaitMode::Spin, &stop, Duration::from_secs(1)));
        t.join().unwrap();
    });
}
