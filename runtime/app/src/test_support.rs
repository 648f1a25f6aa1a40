//! Modules and settings the tests of links between parts share, in this crate and in
//! transport crates (`ferroc-zenoh`'s tests): two parts `a` (10 ms) and `b` (25 ms),
//! modules that record what they saw by a `tag` parameter (tests run in parallel), the
//! links and the call between the two parts, lockstep for both. Compiled for this
//! crate's tests and with the feature `test-support`; not part of the runtime's API.

use crate::builder::{Lockstep, RunningApp, StartOptions};
use ferroc_link::{CallSpec, LinkSpec, Sharing};
use ferroc_module::{In, Module, ModuleType, Out, Parameter, Setup, Timestamp};
use ferroc_ports::service::{ClientPort, PendingResponse, ServicePort};
use std::collections::BTreeMap;
use std::sync::Mutex;
use std::time::Duration;

/// What each module saw, by its `tag` (each test uses its own).
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

/// Milliseconds of model time (in lockstep) since the start.
pub fn model_ms() -> i64 {
    (Timestamp::now().nanos - Timestamp::LOCKSTEP_EPOCH.nanos) / 1_000_000
}

/// Publishes 1, 2, 3, … on `out`, one a step.
pub struct Counter {
    out: Out<u32>,
    n: u32,
}
impl Module for Counter {
    fn update(&mut self) {
        self.n += 1;
        self.out.publish(self.n);
    }
}
impl ModuleType for Counter {
    const NAME: &'static str = "test.Counter";
    fn create(m: &mut Setup<'_>) -> Self {
        Counter {
            out: m.output("out").build(),
            n: 0,
        }
    }
}

/// Publishes `n · step + what it last received` and records what it saw when, and
/// whether its input was stale then.
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
        let stale = if self.input.is_stale() {
            " (stale)"
        } else {
            ""
        };
        let line = format!("{} @{}ms got {got}{stale}", self.path, model_ms());
        note(self.tag.get(), line);
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

/// `a` → `b`: `u32` on change, reliable.
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
/// `b` → `a`: `u32` every 50 ms, best effort.
pub const B_TO_A: LinkSpec<'static> = LinkSpec {
    id: 1,
    from_part: "b",
    to_part: "a",
    model_type: "u32",
    sharing: Sharing::Periodic(Duration::from_millis(50)),
    reliable: false,
    deadline: None,
};
/// `a` calls `b/squarer/square`.
pub const CALL: CallSpec<'static> = CallSpec {
    id: 0,
    client_part: "a",
    server_part: "b",
    service: "b/squarer/square",
};

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

/// Waits (at most 30 s) until the run ends, then stops it.
pub fn run_to_end(app: RunningApp) {
    assert!(
        app.wait_timeout(Duration::from_secs(30)),
        "the run did not end"
    );
    drop(app);
}
