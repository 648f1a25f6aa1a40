//! The principles on numbers (every rule firing and not firing, the policies, rate
//! limits). Behaviours in a built application are tested in `ferroc_app`
//! (`builder/behaviour_tests.rs`).

use super::principles::{Cycle, Principles};
use super::*;
use crate::violations::Monitor;
use std::sync::Arc;

fn monitor(policy: ViolationPolicy) -> (Monitor, Arc<ViolationLog>) {
    let log = Arc::new(ViolationLog::default());
    (Monitor::new("robot/b", policy, log.clone()), log)
}

/// Checks one cycle; returns the (possibly corrected) activity and derived values.
fn run(
    p: &mut Principles,
    m: &mut Monitor,
    (iota, a, r): (f64, f64, f64),
    derived: &mut [f64],
    input_changed: bool,
) -> f64 {
    m.next_cycle();
    let mut c = Cycle {
        activation: iota,
        activity: a,
        target_rating: r,
        derived,
        activity_input_changed: input_changed,
    };
    p.check(&mut c, &["turning"], m);
    c.activity
}

fn count(log: &ViolationLog, rule: Rule) -> u64 {
    log.counts()
        .iter()
        .filter(|c| c.rule == rule)
        .map(|c| c.count)
        .sum()
}

#[test]
fn activation_is_stimulation_times_one_minus_the_largest_inhibition() {
    assert_eq!(activation(0.8, [0.25, 0.5]), 0.8 * 0.5);
    assert_eq!(activation(0.8, []), 0.8);
    assert_eq!(activation(1.0, [1.0]), 0.0);
    assert_eq!(activation(0.0, [0.0]), 0.0);
}

#[test]
fn activity_equal_to_activation_is_fine_and_above_it_is_not() {
    let (mut m, log) = monitor(ViolationPolicy::Warn);
    let mut p = Principles::default();
    assert_eq!(run(&mut p, &mut m, (0.5, 0.5, 1.0), &mut [], false), 0.5);
    assert!(log.counts().is_empty());
    // Under warn the value passes unchanged, and the report names path, rule, values.
    assert_eq!(run(&mut p, &mut m, (0.5, 0.75, 1.0), &mut [], false), 0.75);
    assert_eq!(count(&log, Rule::ActivityLimitation), 1);
    let reports = log.take_reports();
    assert_eq!(reports.len(), 1);
    let r = &reports[0];
    assert!(r.contains("`robot/b`"), "{r}");
    assert!(r.contains("activity limitation"), "{r}");
    assert!(r.contains("activity 0.75 exceeds activation 0.5"), "{r}");
    assert!(r.contains("passed on unchanged"), "{r}");
}

#[test]
fn clamp_corrects_the_activity_to_the_activation() {
    let (mut m, log) = monitor(ViolationPolicy::Clamp);
    let mut p = Principles::default();
    assert_eq!(run(&mut p, &mut m, (0.4, 0.9, 1.0), &mut [], false), 0.4);
    assert_eq!(count(&log, Rule::ActivityLimitation), 1);
}

#[test]
fn meta_signals_out_of_range_are_reported_and_clamped() {
    let (mut m, log) = monitor(ViolationPolicy::Clamp);
    let mut p = Principles::default();
    assert_eq!(run(&mut p, &mut m, (1.0, 1.5, 0.0), &mut [], false), 1.0);
    assert_eq!(
        run(&mut p, &mut m, (1.0, f64::NAN, 0.5), &mut [], false),
        0.0
    );
    assert_eq!(count(&log, Rule::Range), 2);
    // Clamp reports only the first violation of a rule.
    let reports = log.take_reports();
    assert_eq!(reports.len(), 1, "{reports:?}");
    assert!(reports[0].contains("activity = 1.5 is outside [0, 1]"));
    // In range, including the bounds: nothing.
    let (mut m, log) = monitor(ViolationPolicy::Warn);
    run(&mut p, &mut m, (1.0, 1.0, 0.0), &mut [0.0], false);
    run(&mut p, &mut m, (1.0, 0.0, 1.0), &mut [0.0], false);
    assert!(log.counts().is_empty(), "{:?}", log.counts());
}

#[test]
fn goal_state_activity_must_stay_constant() {
    let (mut m, log) = monitor(ViolationPolicy::Warn);
    let mut p = Principles::default();
    run(&mut p, &mut m, (0.8, 0.5, 0.0), &mut [], false);
    // Same activation, target rating 0 twice, activity changed: fires.
    run(&mut p, &mut m, (0.8, 0.6, 0.0), &mut [], false);
    assert_eq!(count(&log, Rule::GoalState), 1);
    let reports = log.take_reports();
    assert!(
        reports[0].contains("activity changed from 0.5 to 0.6"),
        "{reports:?}"
    );
    // Unchanged activity: fine.
    run(&mut p, &mut m, (0.8, 0.6, 0.0), &mut [], false);
    // An activity input changed: allowed to change.
    run(&mut p, &mut m, (0.8, 0.7, 0.0), &mut [], true);
    // The activation changed: allowed to change.
    run(&mut p, &mut m, (0.9, 0.2, 0.0), &mut [], false);
    // Not in the goal state (target rating > 0 now, then only once 0): fine.
    run(&mut p, &mut m, (0.9, 0.3, 0.1), &mut [], false);
    run(&mut p, &mut m, (0.9, 0.4, 0.0), &mut [], false);
    assert_eq!(count(&log, Rule::GoalState), 1);
}

#[test]
fn clamp_keeps_the_goal_state_activity() {
    let (mut m, log) = monitor(ViolationPolicy::Clamp);
    let mut p = Principles::default();
    run(&mut p, &mut m, (0.8, 0.5, 0.0), &mut [], false);
    assert_eq!(run(&mut p, &mut m, (0.8, 0.1, 0.0), &mut [], false), 0.5);
    assert_eq!(run(&mut p, &mut m, (0.8, 0.3, 0.0), &mut [], false), 0.5);
    assert_eq!(count(&log, Rule::GoalState), 2);
}

#[test]
fn derived_activities_stay_below_the_activity() {
    let (mut m, log) = monitor(ViolationPolicy::Warn);
    let mut p = Principles::default();
    let mut d = [0.4];
    run(&mut p, &mut m, (1.0, 0.4, 1.0), &mut d, false);
    assert!(log.counts().is_empty());
    let mut d = [0.6];
    run(&mut p, &mut m, (1.0, 0.4, 1.0), &mut d, false);
    assert_eq!(d, [0.6]);
    assert_eq!(count(&log, Rule::DerivedActivity), 1);
    assert!(log.take_reports()[0].contains("derived activity `turning` = 0.6 exceeds activity 0.4"));
    let (mut m, _) = monitor(ViolationPolicy::Clamp);
    let mut d = [0.6];
    run(&mut p, &mut m, (1.0, 0.4, 1.0), &mut d, false);
    assert_eq!(d, [0.4]);
}

#[test]
fn warn_reports_at_most_once_per_250_cycles_and_counts_every_violation() {
    let (mut m, log) = monitor(ViolationPolicy::Warn);
    let mut p = Principles::default();
    for _ in 0..1000 {
        run(&mut p, &mut m, (0.2, 0.3, 1.0), &mut [], false);
    }
    assert_eq!(count(&log, Rule::ActivityLimitation), 1000);
    let reports = log.take_reports();
    assert_eq!(reports.len(), 4, "{reports:?}");
    assert!(
        reports[1].contains("[249 more since the last report]"),
        "{}",
        reports[1]
    );
}

#[test]
fn stop_hands_the_report_to_the_base() {
    let (mut m, log) = monitor(ViolationPolicy::Stop);
    let mut p = Principles::default();
    run(&mut p, &mut m, (0.2, 0.3, 1.0), &mut [], false);
    let why = m.stop.take().expect("a stop request");
    assert!(
        why.contains("activity limitation") && why.contains("policy stop"),
        "{why}"
    );
    assert!(log.take_reports().is_empty());
}
