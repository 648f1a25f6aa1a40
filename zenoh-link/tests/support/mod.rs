//! What the tests of links over Zenoh share: two small parts `a` (10 ms) and `b`
//! (25 ms) linked both ways, a record of what their modules saw (by a `tag`
//! parameter, since tests run in parallel), free addresses on 127.0.0.1, and starting
//! a part as its own "program" (its own builder and Zenoh session).

#![allow(dead_code)]

use ferroc_runtime::builder::{
    Builder, Conversion, ModuleSpec, Registry, Schedule, StartOptions, StepKind, ThreadSpec,
};
use ferroc_runtime::container::ThreadOptions;
use ferroc_runtime::link::transport::Addresses;
use ferroc_runtime::module::{In, Module, ModuleType, Parameter, Setup, Value};
use ferroc_runtime::port::ConnectOptions;
use ferroc_zenoh::Zenoh;
use std::collections::BTreeMap;
use std::sync::Arc;
use std::time::{Duration, Instant};

pub use ferroc_runtime::test_support::*;

/// Notes, each cycle, whether its input is stale, with the input's age.
pub struct Probe {
    input: In<u32>,
    tag: Parameter<f64>,
}
impl Module for Probe {
    fn update(&mut self) {
        let state = if self.input.is_stale() {
            "stale"
        } else {
            "fresh"
        };
        let age = self.input.age().map_or("none".into(), |a| format!("{a:?}"));
        note(
            self.tag.get(),
            format!("{state} {} age {age}", self.input.get()),
        );
    }
}
impl ModuleType for Probe {
    const NAME: &'static str = "test.Probe";
    fn create(m: &mut Setup<'_>) -> Self {
        Probe {
            input: m.input("in").build(),
            tag: m.param("tag").default(0.0).build(),
        }
    }
}

pub fn registry() -> Registry {
    let mut r = Registry::new();
    r.register::<Echo>()
        .register::<Asker>()
        .register::<Squarer>();
    r.register::<Probe>();
    r.register_call::<i64, i64>();
    r
}

fn add(b: &mut Builder<'_>, path: &str, type_name: &str, params: &[(String, Value)]) {
    b.add_module(ModuleSpec {
        path,
        type_name,
        params,
        queues: &[],
        ports: &[],
        violations: Default::default(),
    })
    .unwrap();
}

fn thread(b: &mut Builder<'_>, part: &str, ms: u64, steps: &[&str]) {
    b.add_thread(ThreadSpec {
        path: part.into(),
        schedule: Schedule::Periodic(Duration::from_millis(ms)),
        options: ThreadOptions::default(),
        steps: steps
            .iter()
            .map(|s| (s.to_string(), StepKind::Update))
            .collect(),
    })
    .unwrap();
}

/// Echo parts `a` (10 ms) and/or `b` (25 ms), linked both ways.
pub fn echoes<'r>(registry: &'r Registry, parts: &[&str], tag: f64) -> Builder<'r> {
    let mut b = Builder::new(registry);
    for &(part, ms, step) in [("a", 10, 1.0), ("b", 25, 100.0)].iter() {
        if parts.contains(&part) {
            let path = format!("{part}/echo");
            let params = [
                ("step".into(), Value::Float(step)),
                ("tag".into(), Value::Float(tag)),
            ];
            add(&mut b, &path, "test.Echo", &params);
            thread(&mut b, part, ms, &[&path]);
        }
    }
    for spec in [A_TO_B, B_TO_A] {
        let from = format!("{}/echo", spec.from_part);
        let to = format!("{}/echo", spec.to_part);
        if parts.contains(&spec.from_part) {
            b.link_out(&spec, (&from, "out"), Conversion::default())
                .unwrap();
        }
        if parts.contains(&spec.to_part) {
            b.link_in(&spec, (&to, "in"), ConnectOptions::default())
                .unwrap();
        }
    }
    b
}

/// Echo part `a` (10 ms) sending to a probe in part `b` (25 ms).
pub fn probed<'r>(registry: &'r Registry, part: &str, tag: f64) -> Builder<'r> {
    let mut b = Builder::new(registry);
    let params = [("tag".to_string(), Value::Float(tag))];
    if part == "a" {
        add(&mut b, "a/echo", "test.Echo", &params);
        thread(&mut b, "a", 10, &["a/echo"]);
        b.link_out(&A_TO_B, ("a/echo", "out"), Conversion::default())
            .unwrap();
    } else {
        add(&mut b, "b/probe", "test.Probe", &params);
        thread(&mut b, "b", 25, &["b/probe"]);
        b.link_in(&A_TO_B, ("b/probe", "in"), ConnectOptions::default())
            .unwrap();
    }
    b
}

/// Asker part `a` (10 ms) calling squarer part `b` (25 ms).
pub fn callers<'r>(
    registry: &'r Registry,
    parts: &[&str],
    tag: f64,
    blocking: bool,
) -> Builder<'r> {
    let mut b = Builder::new(registry);
    if parts.contains(&"a") {
        let params = [
            ("tag".to_string(), Value::Float(tag)),
            ("blocking".to_string(), Value::Bool(blocking)),
        ];
        add(&mut b, "a/asker", "test.Asker", &params);
        b.call_out(&CALL, ("a/asker", "ask")).unwrap();
        thread(&mut b, "a", 10, &["a/asker"]);
    }
    if parts.contains(&"b") {
        add(&mut b, "b/squarer", "test.Squarer", &[]);
        b.call_in(&CALL, ("b/squarer", "square")).unwrap();
        thread(&mut b, "b", 25, &["b/squarer"]);
    }
    b
}

/// A free address on 127.0.0.1 (below the ephemeral range: see `ferroc_testkit`).
pub fn free_port() -> String {
    ferroc_testkit::free_address()
}

/// Parts `a` and `b` at free addresses.
pub fn two_peers() -> BTreeMap<String, String> {
    [
        ("a".to_string(), free_port()),
        ("b".to_string(), free_port()),
    ]
    .into()
}

/// The Zenoh network of `part` among `peers` (application `app`).
pub fn zenoh(app: &str, part: &str, peers: &BTreeMap<String, String>) -> Arc<Zenoh> {
    let addresses = Addresses {
        part: part.into(),
        listen: peers[part].clone(),
        peers: peers.clone(),
    };
    Arc::new(Zenoh::new(app, addresses, None).unwrap())
}

/// Running freely for `cycles` cycles.
pub fn free(cycles: u64) -> StartOptions {
    StartOptions {
        limit: Some(cycles),
        ..StartOptions::default()
    }
}

/// `options` with the Zenoh network of `part`.
pub fn over_zenoh(
    mut options: StartOptions,
    app: &str,
    part: &str,
    peers: &BTreeMap<String, String>,
) -> StartOptions {
    options.network = Some(zenoh(app, part, peers));
    options
}

/// Waits (at most `limit`) until `done` holds.
pub fn eventually(limit: Duration, mut done: impl FnMut() -> bool) -> bool {
    let start = Instant::now();
    while start.elapsed() < limit {
        if done() {
            return true;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    done()
}
