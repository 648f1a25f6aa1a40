//! What a step can ask about the cycle it runs in: the period of its thread container
//! ([`period`]). The container tells it before it runs its steps, so a module needs no
//! parameter of its own that repeats the model's `period="40ms"`.
//!
//! In lockstep a periodic container's cycles lie exactly `period` apart in model time
//! ([`Timestamp::now`](crate::Timestamp::now) advances by it from one cycle to the
//! next); running freely they start at deadlines `period` apart, and a cycle that
//! overran makes the container skip the deadlines it missed. A simulation that steps
//! by [`period`] runs the same in both; one that must know how much time really passed
//! reads [`Timestamp::now`](crate::Timestamp::now) each cycle.

use std::cell::Cell;
use std::time::Duration;

thread_local! {
    /// The container running on this thread: `None` outside a container's cycle,
    /// `Some(None)` in a data-triggered or continuous one.
    static PERIOD: Cell<Option<Option<Duration>>> = const { Cell::new(None) };
}

/// The period of the thread container running the current step (`period="40ms"`):
/// `None` for a data-triggered or continuous container, and outside a step (in
/// `create`, or in a test that calls a step directly without [`set_period`]).
#[inline]
pub fn period() -> Option<Duration> {
    PERIOD.with(Cell::get).flatten()
}

/// Whether the current thread runs a thread container's cycle (whatever its trigger).
#[inline]
pub fn in_cycle() -> bool {
    PERIOD.with(Cell::get).is_some()
}

/// Tells the steps about to run on this thread the period of their container (`None`
/// for data-triggered and continuous ones); `ferroc-exec` calls it before every cycle,
/// a test of a module may call it before calling a step. [`leave_cycle`] undoes it.
pub fn set_period(period: Option<Duration>) {
    PERIOD.with(|p| p.set(Some(period)));
}

/// This thread runs no container's cycle any more.
pub fn leave_cycle() {
    PERIOD.with(|p| p.set(None));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_step_reads_the_period_its_container_set() {
        assert_eq!((period(), in_cycle()), (None, false));
        set_period(Some(Duration::from_millis(40)));
        assert_eq!(period(), Some(Duration::from_millis(40)));
        set_period(None);
        assert_eq!((period(), in_cycle()), (None, true));
        leave_cycle();
        assert!(!in_cycle());
    }
}
