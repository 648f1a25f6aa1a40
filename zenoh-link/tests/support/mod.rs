//! What the tests of links over Zenoh share: two small parts `a` (10 ms) and `b`
//! (25 ms) linked both ways, a record of what their modules saw (by a `tag`
//! parameter, since tests run in parallel), free addresses on 127.0.0.1, and starting
//! a part as its own "program" (its own builder and Zenoh session).

#![allow(dead_code)]

use ferroc_runtime::builder::{
    Builder, Conversion, Lockstep, ModuleSpec, Registry, RunningApp, Schedule, StartOptions,
    StepKind, ThreadSpec,
};
use ferroc_runtime::container::ThreadOptions;
use ferroc_runtime::link::transport::Addresses;
use ferroc_runtime::link::{CallSpec, LinkSpec, Sharing};
use ferroc_runtime::module::{In, Module, ModuleType, Out, Parameter, Setup, Timestamp, Value};
use ferroc_runtime::port::ConnectOptions;
use ferroc_runtime::service::{ClientPort, PendingResponse, ServicePort};
use ferroc_zenoh::Zenoh;
use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

static RECORD: Mutex<BTreeMap<u64, Vec<String>>> = Mutex::new(BTreeMap::new());

/// Adds a line to the record of `tag`.
pub fn note(tag: f64, line: String) {
    RECORD
        .lock()
        .unwrap()
        .entry(tag as u64)
        .or_default()
        .push(line);
}

/// Everything noted under `tag`, in order.
pub fn record(tag: u64) -> Vec<String> {
    RECORD
        .lock()
        .unwrap()
        .get(&tag)
        .cloned()
        .unwrap_or_default()
}

/// The lines of `tag` that start with `prefix`.
pub fn lines_of(tag: u64, prefix: &str) -> Vec<String> {
    record(tag)
        .into_iter()
        .filter(|l| l.starts_with(prefix))
        .collect()
}

fn model_ms() -> i64 {
    (Timestamp::now().nanos - Timestamp::LOCKSTEP_EPOCH.nanos) / 1_000_000
}

/// Publishes `n · step + what it last received` and records what it saw when.
pub struct Echo {
    input: In<u32>,
    out: Out<u32>,
    step: Parameter<f64>,
    tag: Parameter<f64>,
    path: String,
    n: u32,
}
impl Module for Echo {
    fn update(&mut self) {
        self.n += 1;
        let got = self.input.get();
        note(
            self.tag.get(),
            format!("{} @{}ms got {got}", self.path, model_ms()),
        );
        self.out.publish(self.n * self.step.get() as u32 + got);
    }
}
impl ModuleType for Echo {
    const NAME: &'static str = "test.Echo";
    fn create(m: &mut Setup<'_>) -> Self {
        Echo {
            input: m.input("in").build(),
            out: m.output("out").build(),
            step: m.param("step").default(1.0).build(),
            tag: m.param("tag").default(0.0).build(),
            path: m.path().to_owned(),
            n: 0,
        }
    }
}

/// Asks `ask` for n² (n = 1, 2, …) asynchronously, or blocking when `blocking` is set.
pub struct Asker {
    ask: ClientPort<i64, i64>,
    pending: Option<PendingResponse<i64>>,
    n: i64,
    blocking: Parameter<bool>,
    tag: Parameter<f64>,
}
impl Module for Asker {
    fn update(&mut self) {
        let tag = self.tag.get();
        if self.blocking.get() {
            self.n += 1;
            let answer = self.ask.call(self.n);
            note(tag, format!("{} → {answer:?}", self.n));
            return;
        }
        let mut event = String::from("waits");
        if let Some(pending) = self.pending.take() {
            match pending.try_take() {
                Ok(answer) => event = format!("answer {answer:?}"),
                Err(pending) => self.pending = Some(pending),
            }
        }
        if self.pending.is_none() {
            self.n += 1;
            self.pending = self.ask.call_async(self.n).ok();
            event.push_str(&format!(", asks {}", self.n));
        }
        note(tag, format!("a @{}ms {event}", model_ms()));
    }
}
impl ModuleType for Asker {
    const NAME: &'static str = "test.Asker";
    fn create(m: &mut Setup<'_>) -> Self {
        Asker {
            ask: m.client("ask").timeout(Duration::from_secs(5)).build(),
            pending: None,
            n: 0,
            blocking: m.param("blocking").default(false).build(),
            tag: m.param("tag").default(0.0).build(),
        }
    }
}

/// Serves `square` in its step.
pub struct Squarer {
    square: ServicePort<i64, i64>,
}
impl Module for Squarer {
    fn update(&mut self) {
        self.square.serve_pending(|x| x * x);
    }
}
impl ModuleType for Squarer {
    const NAME: &'static str = "test.Squarer";
    fn create(m: &mut Setup<'_>) -> Self {
        Squarer {
            square: m.service("square").build(),
        }
    }
}

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

pub const A_TO_B: LinkSpec<'static> = LinkSpec {
    id: 0,
    from_part: "a",
    to_part: "b",
    model_type: "u32",
    sharing: Sharing::OnChange {
        min_interval: Duration::ZERO,
    },
    reliable: true,
    deadline: None,
};
pub const B_TO_A: LinkSpec<'static> = LinkSpec {
    id: 1,
    from_part: "b",
    to_part: "a",
    model_type: "u32",
    sharing: Sharing::Periodic(Duration::from_millis(50)),
    reliable: false,
    deadline: None,
};
pub const CALL: CallSpec<'static> = CallSpec {
    id: 0,
    client_part: "a",
    server_part: "b",
    service: "b/squarer/square",
};

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

/// A free address on 127.0.0.1.
pub fn free_port() -> String {
    let l = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    l.local_addr().unwrap().to_string()
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

/// Lockstep for parts `a` (10 ms) and `b` (25 ms), each container `cycles` cycles.
pub fn lockstep(cycles: u64) -> StartOptions {
    StartOptions {
        limit: Some(cycles),
        lockstep: Some(Lockstep {
            periods: vec![Duration::from_millis(10), Duration::from_millis(25)],
            until: None,
        }),
        network: None,
    }
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

/// Waits (at most 30 s) until the run ends, then stops it.
pub fn run_to_end(app: RunningApp) {
    assert!(
        app.wait_timeout(Duration::from_secs(30)),
        "the run did not end"
    );
    drop(app);
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
