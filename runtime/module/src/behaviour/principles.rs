//! The iB2C principles every behaviour keeps, checked once per cycle: meta signals in
//! [0, 1], activity ≤ activation, goal-state activity, derived activities ≤ activity
//! (finroc.md §4.2 R1, R5, R6, R7). Pure bookkeeping on numbers, so every rule can be
//! tested without ports or threads.

use crate::violations::{Action, Monitor, Rule};
use std::fmt::Write as _;

/// Rounding slack of the comparisons: an activity computed as `x · ι` may exceed ι by
/// an ulp; nothing a behaviour means to do is that small.
pub const TOLERANCE: f64 = 1e-12;

/// Whether two meta values are the same for the goal-state rule (FINROC compares with
/// `rrlib::math::IsEqual`).
fn same(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9
}

/// Rule R1 for one value; under a correcting policy NaN becomes 0 and the value is
/// clamped into [0, 1].
pub(crate) fn check_range(monitor: &mut Monitor, what: impl std::fmt::Display, value: &mut f64) {
    if (0.0..=1.0).contains(value) {
        return;
    }
    let v = *value;
    let action = monitor.violated(Rule::Range, |t| {
        let _ = write!(t, "{what} = {v} is outside [0, 1]");
    });
    if action == Action::Correct {
        *value = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
    }
}

/// One cycle's meta values as the behaviour computed them (corrected in place under a
/// correcting policy).
pub(crate) struct Cycle<'d> {
    pub activation: f64,
    pub activity: f64,
    pub target_rating: f64,
    pub derived: &'d mut [f64],
    /// An activity input (a fusion channel's `in/k/activity`, any input of type
    /// `Activity`) has a new value since the last cycle.
    pub activity_input_changed: bool,
}

#[derive(Clone, Copy)]
struct Last {
    activation: f64,
    activity: f64,
    target_rating: f64,
}

/// What the principles remember from one cycle to the next.
#[derive(Default)]
pub(crate) struct Principles {
    last: Option<Last>,
}

impl Principles {
    /// Checks a cycle's outputs (the inputs' ranges are checked where they are read).
    pub fn check(&mut self, c: &mut Cycle<'_>, derived_names: &[&str], monitor: &mut Monitor) {
        check_range(monitor, "activity", &mut c.activity);
        check_range(monitor, "target rating", &mut c.target_rating);
        for (d, name) in c.derived.iter_mut().zip(derived_names) {
            check_range(monitor, name, d);
        }
        let (a, iota) = (c.activity, c.activation);
        if a > iota + TOLERANCE {
            let action = monitor.violated(Rule::ActivityLimitation, |t| {
                let _ = write!(t, "activity {a} exceeds activation {iota}");
            });
            if action == Action::Correct {
                c.activity = iota;
            }
        }
        if let Some(last) = self.last {
            let goal_state = c.target_rating == 0.0 && last.target_rating == 0.0;
            if goal_state
                && same(c.activation, last.activation)
                && !c.activity_input_changed
                && !same(c.activity, last.activity)
            {
                let (now, before) = (c.activity, last.activity);
                let action = monitor.violated(Rule::GoalState, |t| {
                    let _ = write!(
                        t,
                        "target rating 0 in two cycles with unchanged activation {iota}, \
                         but activity changed from {before} to {now}"
                    );
                });
                if action == Action::Correct {
                    c.activity = before.min(c.activation);
                }
            }
        }
        let a = c.activity;
        for (d, name) in c.derived.iter_mut().zip(derived_names) {
            if *d > a + TOLERANCE {
                let v = *d;
                let action = monitor.violated(Rule::DerivedActivity, |t| {
                    let _ = write!(t, "derived activity `{name}` = {v} exceeds activity {a}");
                });
                if action == Action::Correct {
                    *d = a;
                }
            }
        }
        self.last = Some(Last {
            activation: c.activation,
            activity: c.activity,
            target_rating: c.target_rating,
        });
    }
}

/// The activation ι = s · (1 − i), i the largest of the given (connected) inhibitions,
/// 0 when there are none.
pub fn activation(stimulation: f64, inhibitions: impl IntoIterator<Item = f64>) -> f64 {
    let inhibition = inhibitions.into_iter().fold(0.0_f64, f64::max);
    stimulation * (1.0 - inhibition)
}
