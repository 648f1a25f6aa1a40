//! `ferroc_std.Fusion` built and run like `ferroc run` builds it: the formulas through
//! ports, and the goal-state principle with changing channel activities.

mod common;

use common::{run_free, wire};
use ferroc_runtime::builder::{Builder, Registry, RunningApp};
use ferroc_runtime::module::{MetaType, Module, ModuleType, Out, Setup, Value};
use ferroc_runtime::port::{ConnectOptions, CopyInputPort};
use std::time::Duration;

/// An activity that falls by 1/64 each cycle from 1 (a channel in motion).
struct Ramp {
    out: Out<f64>,
    n: u32,
}
impl Module for Ramp {
    fn update(&mut self) {
        self.out.publish(1.0 - self.n.min(64) as f64 / 64.0);
        self.n += 1;
    }
}
impl ModuleType for Ramp {
    const NAME: &'static str = "test.Ramp";
    fn create(m: &mut Setup<'_>) -> Self {
        Ramp {
            out: m.output("activity").meta(MetaType::Activity).build(),
            n: 0,
        }
    }
}

fn registry() -> Registry {
    let mut r = common::registry();
    r.register::<Ramp>();
    r
}

fn add(b: &mut Builder<'_>, path: &str, ty: &str, params: &[(&str, Value)]) {
    common::add(b, path, ty, params, &[]).unwrap();
}

fn run(b: Builder<'_>, order: &[&str], cycles: u64) -> RunningApp {
    run_free(b, order, Duration::from_micros(200), cycles)
}

fn probe(b: &Builder<'_>, path: &str, port: &str) -> CopyInputPort<f64> {
    let p = CopyInputPort::new("probe");
    b.output(path, port)
        .unwrap()
        .connect(&p.handle(), ConnectOptions::default())
        .unwrap();
    p
}

#[test]
fn a_weighted_average_through_ports() {
    let registry = registry();
    let mut b = Builder::new(&registry);
    add(
        &mut b,
        "u0",
        "ferroc_std.Constant",
        &[("value", Value::Float(2.0))],
    );
    add(
        &mut b,
        "u1",
        "ferroc_std.Constant",
        &[("value", Value::Float(4.0))],
    );
    add(
        &mut b,
        "a0",
        "ferroc_std.ConstantActivity",
        &[("value", Value::Float(0.75))],
    );
    add(
        &mut b,
        "a1",
        "ferroc_std.ConstantActivity",
        &[("value", Value::Float(0.25))],
    );
    add(
        &mut b,
        "r",
        "ferroc_std.ConstantActivity",
        &[("value", Value::Float(0.5))],
    );
    add(
        &mut b,
        "s",
        "ferroc_std.ConstantActivity",
        &[("value", Value::Float(0.5))],
    );
    add(
        &mut b,
        "fusion",
        "ferroc_std.Fusion",
        &[("method", Value::Text("weighted_average".into()))],
    );
    for k in 0..2 {
        let (a, u) = (["a0", "a1"][k], ["u0", "u1"][k]);
        wire(
            &mut b,
            (a, "activity"),
            ("fusion", &format!("in/{k}/activity")),
        );
        wire(
            &mut b,
            ("r", "activity"),
            ("fusion", &format!("in/{k}/target_rating")),
        );
        wire(&mut b, (u, "value"), ("fusion", &format!("in/{k}/value")));
    }
    wire(&mut b, ("s", "activity"), ("fusion", "stimulation"));
    let (value, activity, rating) = (
        probe(&b, "fusion", "value"),
        probe(&b, "fusion", "activity"),
        probe(&b, "fusion", "target_rating"),
    );
    let app = run(b, &["u0", "u1", "a0", "a1", "r", "s", "fusion"], 3);
    assert_eq!(value.get(), 0.75 * 2.0 + 0.25 * 4.0);
    // (0.75² + 0.25²) / 1 · ι (0.5)
    assert_eq!(activity.get(), 0.3125);
    assert_eq!(rating.get(), 0.5);
    assert!(
        app.violation_counts().is_empty(),
        "{:?}",
        app.violation_counts()
    );
}

#[test]
fn changing_channel_activities_are_no_goal_state_violation() {
    let registry = registry();
    let mut b = Builder::new(&registry);
    add(&mut b, "ramp", "test.Ramp", &[]);
    add(
        &mut b,
        "zero",
        "ferroc_std.ConstantActivity",
        &[("value", Value::Float(0.0))],
    );
    add(
        &mut b,
        "u",
        "ferroc_std.Constant",
        &[("value", Value::Float(1.0))],
    );
    add(
        &mut b,
        "fusion",
        "ferroc_std.Fusion",
        &[
            ("channels", Value::Int(1)),
            ("stimulation_mode", Value::Text("enabled".into())),
        ],
    );
    wire(&mut b, ("ramp", "activity"), ("fusion", "in/0/activity"));
    wire(
        &mut b,
        ("zero", "activity"),
        ("fusion", "in/0/target_rating"),
    );
    wire(&mut b, ("u", "value"), ("fusion", "in/0/value"));
    let activity = probe(&b, "fusion", "activity");
    // Target rating 0 and activation 1 throughout; the activity follows the ramp.
    let app = run(b, &["ramp", "zero", "u", "fusion"], 20);
    assert_eq!(activity.get(), 1.0 - 19.0 / 64.0);
    assert!(
        app.violation_counts().is_empty(),
        "{:?}",
        app.violation_counts()
    );
}
