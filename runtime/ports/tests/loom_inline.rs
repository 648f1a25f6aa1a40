//! Model-checked tests of [`InlineGate`], the state word of a `wait="inline"`
//! container: under every interleaving (up to loom's preemption bound) of threads that
//! deliver a value and then arrive at the gate, cycles never overlap, the last cycle
//! sees every value delivered (nothing lost), no cycle runs without a trigger owed,
//! and nothing runs after the gate is closed.
//!
//! Run: `RUSTFLAGS="--cfg loom" cargo test -p ferroc-ports --release --test loom_inline`
#![cfg(loom)]

use ferroc_ports::port::{Arrival, InlineGate};
use loom::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use loom::sync::Arc;
use loom::thread;

/// What the container's cycles saw.
#[derive(Default)]
struct Seen {
    /// Values delivered so far (the "input").
    delivered: AtomicUsize,
    /// The number of values the latest cycle saw.
    last: AtomicUsize,
    cycles: AtomicUsize,
    running: AtomicBool,
}

impl Seen {
    /// A cycle: never two at once; reads every value delivered so far.
    fn cycle(&self) {
        assert!(
            !self.running.swap(true, Ordering::SeqCst),
            "two cycles ran at once"
        );
        let now = self.delivered.load(Ordering::SeqCst);
        assert!(now >= self.last.load(Ordering::SeqCst), "values went back");
        self.last.store(now, Ordering::SeqCst);
        self.cycles.fetch_add(1, Ordering::SeqCst);
        self.running.store(false, Ordering::SeqCst);
    }

    /// A writer's delivery: the value first, then the trigger.
    fn deliver(&self, gate: &InlineGate) -> Arrival {
        self.delivered.fetch_add(1, Ordering::SeqCst);
        gate.arrive(|| self.cycle())
    }
}

/// Two threads deliver at once (two links' callbacks, say): whoever runs the last
/// cycle ran it after both values were there, and there were at most two cycles.
#[test]
fn two_deliverers_lose_nothing_and_never_overlap() {
    loom::model(|| {
        let gate = Arc::new(InlineGate::new());
        let seen = Arc::new(Seen::default());
        let (g, s) = (Arc::clone(&gate), Arc::clone(&seen));
        let t = thread::spawn(move || s.deliver(&g));
        let here = seen.deliver(&gate);
        let there = t.join().unwrap();
        assert!(here != Arrival::Closed && there != Arrival::Closed);
        assert!(here == Arrival::Ran || there == Arrival::Ran, "someone ran");
        assert_eq!(seen.last.load(Ordering::SeqCst), 2, "a value was lost");
        let cycles = seen.cycles.load(Ordering::SeqCst);
        assert!((1..=2).contains(&cycles), "{cycles} cycles for two values");
        // Both done: the gate is idle again, so it closes.
        assert!(gate.close());
    });
}

/// The container's own thread does its chores (changes between cycles) while a value
/// arrives: the value's cycle runs (before or after the chores, never during them).
#[test]
fn chores_and_a_delivery_take_turns() {
    loom::model(|| {
        let gate = Arc::new(InlineGate::new());
        let seen = Arc::new(Seen::default());
        let (g, s) = (Arc::clone(&gate), Arc::clone(&seen));
        let t = thread::spawn(move || s.deliver(&g));
        let chores_done = gate.chores(
            || {
                assert!(
                    !seen.running.load(Ordering::SeqCst),
                    "chores during a cycle"
                );
            },
            || seen.cycle(),
        );
        t.join().unwrap();
        let _ = chores_done;
        assert_eq!(seen.last.load(Ordering::SeqCst), 1, "the value was lost");
        assert_eq!(seen.cycles.load(Ordering::SeqCst), 1);
    });
}

/// Closing while a value arrives: either the value's cycle ran before the gate closed
/// (and close waited for it), or the arrival found the gate closed and ran nothing;
/// never a cycle after a successful close.
#[test]
fn nothing_runs_after_close() {
    loom::model(|| {
        let gate = Arc::new(InlineGate::new());
        let seen = Arc::new(Seen::default());
        let closed = Arc::new(AtomicBool::new(false));
        let (g, s, c) = (Arc::clone(&gate), Arc::clone(&seen), Arc::clone(&closed));
        let t = thread::spawn(move || {
            s.delivered.fetch_add(1, Ordering::SeqCst);
            g.arrive(|| {
                assert!(!c.load(Ordering::SeqCst), "a cycle after close");
                s.cycle();
            })
        });
        while !gate.close() {
            thread::yield_now();
        }
        closed.store(true, Ordering::SeqCst);
        let arrival = t.join().unwrap();
        let cycles = seen.cycles.load(Ordering::SeqCst);
        match arrival {
            Arrival::Ran => assert_eq!(cycles, 1),
            Arrival::Closed => assert_eq!(cycles, 0),
            Arrival::Left => panic!("nobody else was running"),
        }
    });
}
