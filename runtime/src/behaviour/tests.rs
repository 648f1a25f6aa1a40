//! The principles on numbers (every rule firing and not firing, the policies, rate
//! limits), then behaviours in a built application (activation from the wiring, the
//! base's interface, clamp and stop end to end).

use super::principles::{Cycle, Principles};
use super::report::Monitor;
use super::*;
use crate::builder::{Builder, ModuleSpec, Registry, Schedule, StepKind, ThreadSpec};
use crate::container::ThreadOptions;
use crate::module::{Direction, Role, Value};
use crate::port::{ConnectOptions, CopyInputPort};
use std::sync::Arc;
use std::time::Duration;

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

// ----- behaviours in an application -----

/// Activity = activation + `excess`; publishes the activation it saw on `seen`.
struct Greedy {
    seen: Out<f64>,
    excess: Parameter<f64>,
}

impl Behaviour for Greedy {
    const NAME: &'static str = "test.Greedy";
    const DERIVED: &'static [&'static str] = &["half"];
    fn create(m: &mut Setup<'_>) -> Self {
        Greedy {
            seen: m.output("seen").build(),
            excess: m.param("excess").default(0.0).build(),
        }
    }
    fn transfer(&mut self, activation: f64, derived: &mut [f64]) -> BehaviourOutput {
        self.seen.publish(activation);
        let activity = activation + self.excess.get();
        derived[0] = activation / 2.0;
        BehaviourOutput {
            activity,
            target_rating: 1.0,
        }
    }
}

/// A plain module publishing two meta values from parameters.
struct Source {
    a: Out<f64>,
    b: Out<f64>,
    va: Parameter<f64>,
    vb: Parameter<f64>,
}
impl Module for Source {
    fn update(&mut self) {
        self.a.publish(self.va.get());
        self.b.publish(self.vb.get());
    }
}
impl ModuleType for Source {
    const NAME: &'static str = "test.Source";
    fn create(m: &mut Setup<'_>) -> Self {
        Source {
            a: m.output("a").meta(MetaType::Activity).build(),
            b: m.output("b").meta(MetaType::Activity).build(),
            va: m.param("va").meta(MetaType::Activity).default(0.6).build(),
            vb: m.param("vb").meta(MetaType::Activity).default(0.5).build(),
        }
    }
}

fn registry() -> Registry {
    let mut r = Registry::new();
    r.register_behaviour::<Greedy>().register::<Source>();
    r
}

fn spec<'a>(path: &'a str, ty: &'a str, params: &'a [(String, Value)]) -> ModuleSpec<'a> {
    ModuleSpec {
        path,
        type_name: ty,
        params,
        queues: &[],
        ports: &[],
        violations: ViolationPolicy::Warn,
    }
}

fn probe(b: &Builder<'_>, path: &str, port: &str) -> CopyInputPort<f64> {
    let p = CopyInputPort::<f64>::new("probe");
    b.output(path, port)
        .unwrap()
        .connect(&p.handle(), ConnectOptions::default())
        .unwrap();
    p
}

fn thread(steps: &[&str]) -> ThreadSpec {
    ThreadSpec {
        path: "main".into(),
        schedule: Schedule::Periodic(Duration::from_micros(200)),
        options: ThreadOptions::default(),
        steps: steps
            .iter()
            .map(|p| (p.to_string(), StepKind::Update))
            .collect(),
    }
}

#[test]
fn the_registry_reports_the_meta_interface_of_a_behaviour() {
    let i = registry().interface("test.Greedy").unwrap();
    assert_eq!(i.kind, Kind::Behaviour);
    let port = |n: &str| i.port(n).unwrap_or_else(|| panic!("no port {n}"));
    for (name, dir, ty) in [
        ("stimulation", Direction::In, "Stimulation"),
        ("inhibition/0", Direction::In, "Inhibition"),
        ("activity", Direction::Out, "Activity"),
        ("target_rating", Direction::Out, "TargetRating"),
        ("activity/half", Direction::Out, "Activity"),
    ] {
        assert_eq!(
            (port(name).dir, port(name).role),
            (dir, Role::Meta),
            "{name}"
        );
        assert_eq!(port(name).model_type, ty, "{name}");
    }
    assert_eq!(port("seen").role, Role::Plain);
    assert!(i.port("inhibition/1").is_none());
    let mode = i.param("stimulation_mode").unwrap();
    assert_eq!(mode.choices, ["auto", "enabled", "disabled"]);
    assert_eq!(mode.default.as_deref(), Some("auto"));
    assert_eq!(i.param("inhibitions").unwrap().model_type, "u32");
}

/// Builds `src` (a: 0.6, b: 0.5) and a Greedy `b` with 2 inhibitions, `b.a → stimulation`
/// and `src.b → inhibition/0`; runs 5 cycles; returns (seen activation, activity).
fn activation_with(mode: &str, connect_stimulation: bool) -> (f64, f64) {
    let registry = registry();
    let mut b = Builder::new(&registry);
    b.add_module(spec("src", "test.Source", &[])).unwrap();
    let params = [
        ("stimulation_mode".to_string(), Value::Text(mode.into())),
        ("inhibitions".to_string(), Value::Int(2)),
    ];
    b.add_module(spec("beh", "test.Greedy", &params)).unwrap();
    let wire = |b: &mut Builder<'_>, from: &str, to: &str| {
        b.connect(
            ("src", from),
            ("beh", to),
            Default::default(),
            Default::default(),
        )
        .unwrap()
    };
    if connect_stimulation {
        wire(&mut b, "a", "stimulation");
    }
    wire(&mut b, "b", "inhibition/0");
    let (seen, activity) = (probe(&b, "beh", "seen"), probe(&b, "beh", "activity"));
    b.add_thread(thread(&["src", "beh"])).unwrap();
    let mut app = b.start(Some(5)).unwrap();
    app.join();
    (seen.get(), activity.get())
}

#[test]
fn the_base_computes_the_activation_from_mode_and_connected_inputs() {
    // auto: 0.6 · (1 − max(0.5, unconnected inhibition/1 ignored))
    assert_eq!(activation_with("auto", true), (0.3, 0.3));
    // auto with nothing on the stimulation: never active.
    assert_eq!(activation_with("auto", false), (0.0, 0.0));
    // enabled ignores the stimulation input; disabled forces 0.
    assert_eq!(activation_with("enabled", true).0, 0.5);
    assert_eq!(activation_with("disabled", true).0, 0.0);
}

fn greedy_app(policy: ViolationPolicy) -> (crate::builder::RunningApp, CopyInputPort<f64>) {
    let registry = registry();
    let mut b = Builder::new(&registry);
    b.add_module(spec("robot/src", "test.Source", &[])).unwrap();
    // Activity = activation 0.6 at first; the excess is raised while it runs.
    b.add_module(ModuleSpec {
        violations: policy,
        ..spec("robot/greedy", "test.Greedy", &[])
    })
    .unwrap();
    b.connect(
        ("robot/src", "a"),
        ("robot/greedy", "stimulation"),
        Default::default(),
        Default::default(),
    )
    .unwrap();
    let activity = probe(&b, "robot/greedy", "activity");
    b.add_thread(ThreadSpec {
        schedule: Schedule::Periodic(Duration::from_millis(1)),
        ..thread(&["robot/src", "robot/greedy"])
    })
    .unwrap();
    let app = b.start(Some(100)).unwrap();
    app.set_parameter("robot/greedy", "excess", &Value::Float(0.25))
        .unwrap();
    (app, activity)
}

#[test]
fn under_warn_the_violating_activity_is_published() {
    let (mut app, activity) = greedy_app(ViolationPolicy::Warn);
    app.join();
    assert_eq!(activity.get(), 0.85);
    let reports = app.take_violation_reports();
    assert!(!reports.is_empty() && reports.len() <= 1, "{reports:?}");
    assert!(
        reports[0].contains("activity 0.85 exceeds activation 0.6"),
        "{reports:?}"
    );
}

#[test]
fn under_clamp_an_application_reports_once_and_publishes_the_activation() {
    let (mut app, activity) = greedy_app(ViolationPolicy::Clamp);
    app.join();
    assert_eq!(activity.get(), 0.6);
    let reports = app.take_violation_reports();
    assert_eq!(reports.len(), 1, "{reports:?}");
    assert!(reports[0].contains("`robot/greedy` (activity limitation)"));
    assert!(reports[0].contains("activity 0.85 exceeds activation 0.6"));
    let counts = app.violation_counts();
    assert_eq!(counts.len(), 1, "{counts:?}");
    assert!(counts[0].count > 0 && counts[0].policy == ViolationPolicy::Clamp);
    assert!(app.panics().is_empty());
}

#[test]
fn under_stop_the_module_is_stopped_like_a_panic() {
    let (mut app, _) = greedy_app(ViolationPolicy::Stop);
    app.join();
    let panics = app.panics();
    assert_eq!(panics.len(), 1, "{panics:?}");
    assert!(
        panics[0].starts_with(
            "`robot/greedy:update` was stopped: iB2C principle violation in `robot/greedy` \
             (activity limitation)"
        ),
        "{}",
        panics[0]
    );
    assert_eq!(app.violation_counts()[0].count, 1);
}
