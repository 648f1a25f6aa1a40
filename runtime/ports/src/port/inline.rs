//! [`InlineGate`]: the state word of a `wait="inline"` container, whose cycles run in
//! the thread that delivers its trigger value instead of a thread of its own.
//!
//! Several threads may deliver at once (two links' Zenoh callbacks, an in-process
//! writer). The gate lets exactly one of them run cycles at a time; one that arrives
//! while a cycle runs does not wait: it leaves a mark, and the running thread runs one
//! more cycle after its own (run to completion). So no trigger is lost (the cycle
//! after the mark starts after the value was delivered, and sees it), a cycle never
//! runs twice at once, and a delivering thread never blocks on another. Like a
//! [`Wakeup`](super::Wakeup), several triggers during one cycle count once.
//!
//! States: `IDLE` (no cycle runs), `RUNNING` (one runs), `AGAIN` (one runs and another
//! is owed), `CLOSED` (the container has stopped: nothing runs any more). Only the
//! running thread leaves `RUNNING`/`AGAIN` for `IDLE` or `RUNNING`; others only move
//! `IDLE → RUNNING` (they become the runner), `RUNNING → AGAIN` and `IDLE → CLOSED`.
//! `tests/loom_inline.rs` checks the rules under every interleaving.

use crate::sync::{AtomicUsize, Ordering};

const IDLE: usize = 0;
const RUNNING: usize = 1;
const AGAIN: usize = 2;
const CLOSED: usize = 3;

/// What [`InlineGate::arrive`] did with a trigger.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Arrival {
    /// The caller ran the cycle (and every one owed meanwhile).
    Ran,
    /// Another thread runs a cycle and will run one more for this trigger.
    Left,
    /// The gate is closed: nothing runs.
    Closed,
}

/// The state word of an inline container (see the module docs).
#[derive(Debug)]
pub struct InlineGate {
    state: AtomicUsize,
}

impl Default for InlineGate {
    fn default() -> Self {
        InlineGate {
            state: AtomicUsize::new(IDLE),
        }
    }
}

impl InlineGate {
    /// A gate with no cycle running.
    pub fn new() -> Self {
        Self::default()
    }

    /// A trigger value was delivered (before this call): runs `cycle` on this thread
    /// if no other thread is running one, and again for every trigger that arrives
    /// while it runs; else leaves the cycle to the thread that is running one.
    pub fn arrive(&self, mut cycle: impl FnMut()) -> Arrival {
        match self.enter() {
            Some(()) => {
                self.run_from(&mut cycle);
                Arrival::Ran
            }
            None if self.state.load(Ordering::SeqCst) == CLOSED => Arrival::Closed,
            None => Arrival::Left,
        }
    }

    /// Runs `chores` (work between cycles: changes of the container) if no cycle runs,
    /// then the cycles triggers asked for meanwhile; false (nothing done) if a cycle
    /// runs now or the gate is closed.
    pub fn chores(&self, chores: impl FnOnce(), mut cycle: impl FnMut()) -> bool {
        if (self.state)
            .compare_exchange(IDLE, RUNNING, Ordering::SeqCst, Ordering::SeqCst)
            .is_err()
        {
            return false;
        }
        chores();
        self.finish(&mut cycle);
        true
    }

    /// Closes the gate if no cycle runs (true): no cycle runs after it. False while one
    /// runs; call again later.
    pub fn close(&self) -> bool {
        match (self.state).compare_exchange(IDLE, CLOSED, Ordering::SeqCst, Ordering::SeqCst) {
            Ok(_) => true,
            Err(now) => now == CLOSED,
        }
    }

    /// Takes the gate for a cycle (`Some`), or marks a cycle owed to the runner
    /// (`None`; also when closed).
    fn enter(&self) -> Option<()> {
        let mut now = IDLE;
        loop {
            let next = match now {
                IDLE => RUNNING,
                RUNNING => AGAIN,
                // Already owed (several triggers count once), or closed.
                _ => return None,
            };
            match (self.state).compare_exchange(now, next, Ordering::SeqCst, Ordering::SeqCst) {
                Ok(_) if next == RUNNING => return Some(()),
                Ok(_) => return None,
                Err(seen) => now = seen,
            }
        }
    }

    /// Runs a cycle, then those owed, then leaves the gate idle.
    fn run_from(&self, cycle: &mut impl FnMut()) {
        cycle();
        self.finish(cycle);
    }

    /// Leaves the gate idle, unless a cycle is owed: then runs it (and so on).
    fn finish(&self, cycle: &mut impl FnMut()) {
        loop {
            match (self.state).compare_exchange(RUNNING, IDLE, Ordering::SeqCst, Ordering::SeqCst) {
                Ok(_) => return,
                Err(_) => {
                    // `AGAIN`: only the runner leaves it. The owed cycle starts after
                    // the mark, so it sees the value delivered before it.
                    self.state.store(RUNNING, Ordering::SeqCst);
                    cycle();
                }
            }
        }
    }
}

#[cfg(all(test, not(loom)))]
mod tests {
    use super::*;
    use std::cell::Cell;

    #[test]
    fn a_trigger_during_a_cycle_runs_one_more_cycle_on_the_running_thread() {
        let gate = InlineGate::new();
        let runs = Cell::new(0);
        let outcome = gate.arrive(|| {
            runs.set(runs.get() + 1);
            if runs.get() == 1 {
                // Two triggers while the first cycle runs (from this very thread, as
                // a step writing its own input would): they count once.
                assert_eq!(gate.arrive(|| unreachable!()), Arrival::Left);
                assert_eq!(gate.arrive(|| unreachable!()), Arrival::Left);
                assert!(!gate.chores(|| unreachable!(), || unreachable!()));
                assert!(!gate.close(), "a cycle runs");
            }
        });
        assert_eq!(outcome, Arrival::Ran);
        assert_eq!(runs.get(), 2);
    }

    #[test]
    fn a_wakeup_with_a_runner_calls_it_instead_of_setting_its_flag() {
        use crate::port::{Notify, Wakeup};
        use std::sync::atomic::{AtomicUsize, Ordering};
        use std::sync::Arc;
        let wakeup = Wakeup::new();
        wakeup.notify();
        let calls = Arc::new(AtomicUsize::new(0));
        let c = Arc::clone(&calls);
        let runner = move || {
            c.fetch_add(1, Ordering::SeqCst);
        };
        assert!(wakeup.run_inline(Arc::new(runner)).is_ok());
        wakeup.notify();
        assert_eq!(calls.load(Ordering::SeqCst), 1);
        assert!(
            wakeup.take(),
            "the notification from before the runner stays"
        );
        assert!(!wakeup.take(), "and the runner's left no flag");
        assert!(wakeup.run_inline(Arc::new(|| ())).is_err(), "one runner");
    }

    #[test]
    fn a_closed_gate_runs_nothing() {
        let gate = InlineGate::new();
        assert!(
            gate.chores(|| (), || unreachable!()),
            "idle: the chores run"
        );
        assert!(gate.close());
        assert!(gate.close(), "closing twice is harmless");
        assert_eq!(gate.arrive(|| unreachable!()), Arrival::Closed);
        assert!(!gate.chores(|| unreachable!(), || unreachable!()));
    }
}
