//! Behaviours in a built application (activation from the wiring, the base's
//! interface, clamp and stop end to end); the principles on numbers are tested with
//! the behaviour base in `ferroc_module`.

use crate::builder::{Builder, ModuleSpec, Registry, Schedule, StepKind, ThreadSpec};
use ferroc_exec::ThreadOptions;
use ferroc_module::behaviour::{Behaviour, BehaviourOutput, ViolationPolicy};
use ferroc_module::{
    Direction, Kind, MetaType, Module, ModuleType, Out, Parameter, Role, Setup, Value,
};
use ferroc_ports::port::{ConnectOptions, CopyInputPort};
use std::time::Duration;

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
