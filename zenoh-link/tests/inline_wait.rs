//! `wait="inline"` across two part programs over Zenoh (two builders, two sessions,
//! on 127.0.0.1): the reader's data-triggered container runs its cycle in the thread
//! that delivers the value (Zenoh's callback), sees every value in order, and in
//! lockstep prints exactly what `wait="park"` prints.

mod support;

use ferroc_runtime::builder::{Builder, ModuleSpec, Registry, Schedule, StepKind, ThreadSpec};
use ferroc_runtime::container::ThreadOptions;
use ferroc_runtime::module::{In, Module, ModuleType, Parameter, Setup, Value};
use ferroc_runtime::port::{ConnectOptions, WaitMode};
use std::time::Duration;
use support::*;

/// Notes every value its input got, with the name of the thread that ran the step.
struct Seq {
    input: In<u32>,
    tag: Parameter<f64>,
}
impl Module for Seq {
    fn update(&mut self) {
        if let Some(value) = self.input.changed().then(|| self.input.get()) {
            let thread = std::thread::current();
            let name = thread.name().unwrap_or("?");
            note(
                self.tag.get(),
                format!("b/seq @{}ms {value} on {name}", model_ms()),
            );
        }
    }
}
impl ModuleType for Seq {
    const NAME: &'static str = "test.Seq";
    fn create(m: &mut Setup<'_>) -> Self {
        Seq {
            input: m.input("in").build(),
            tag: m.param("tag").default(0.0).build(),
        }
    }
}

fn registry_with_seq() -> Registry {
    let mut r = registry();
    r.register::<Seq>();
    r
}

/// Part `a`: an echo counting 1, 2, 3 … every 10 ms. Part `b`: `Seq`, in a
/// data-triggered container waiting as `wait` says (its thread is called `b-reader`).
fn parts<'r>(registry: &'r Registry, part: &str, tag: f64, wait: WaitMode) -> Builder<'r> {
    let mut b = Builder::new(registry);
    let params = [("tag".to_string(), Value::Float(tag))];
    let (module, type_name, thread, schedule) = if part == "a" {
        (
            "a/echo",
            "test.Echo",
            "a",
            Schedule::Periodic(Duration::from_millis(10)),
        )
    } else {
        ("b/reader/seq", "test.Seq", "b/reader", Schedule::Data)
    };
    b.add_module(ModuleSpec {
        path: module,
        type_name,
        params: &params,
        queues: &[],
        ports: &[],
        violations: Default::default(),
    })
    .unwrap();
    b.add_thread(ThreadSpec {
        path: thread.into(),
        schedule,
        options: ThreadOptions {
            wait,
            ..ThreadOptions::default()
        },
        steps: vec![(module.to_string(), StepKind::Update)],
    })
    .unwrap();
    if part == "a" {
        b.link_out(&A_TO_B, (module, "out"), Default::default())
            .unwrap();
    } else {
        b.link_in(&A_TO_B, (module, "in"), ConnectOptions::default())
            .unwrap();
    }
    b
}

/// The values `b/seq` noted under `tag`, with the threads that ran the steps.
fn seen(tag: u64) -> Vec<(u32, String)> {
    lines_of(tag, "b/seq")
        .iter()
        .filter_map(|l| {
            let (_, rest) = l.split_once("ms ")?;
            let (value, thread) = rest.split_once(" on ")?;
            Some((value.parse().ok()?, thread.to_string()))
        })
        .collect()
}

#[test]
fn an_inline_reader_sees_every_value_in_order_in_the_delivering_thread() {
    let registry = registry_with_seq();
    let peers = two_peers();
    let start = |part: &str, cycles: u64| {
        let options = over_zenoh(free(cycles), "inline_free", part, &peers);
        (parts(&registry, part, 21.0, WaitMode::Inline).start_with(options)).unwrap()
    };
    // The reader first, so that it hears the writer's first values.
    let b = start("b", u64::MAX);
    let a = start("a", 100_000);
    let enough = eventually(Duration::from_secs(20), || seen(21).len() >= 40);
    a.stop();
    b.stop();
    drop((a, b));
    let seen = seen(21);
    assert!(enough, "too few values: {seen:?}");
    // Every value once, in order, from wherever the reader started hearing.
    let values: Vec<u32> = seen.iter().map(|(v, _)| *v).collect();
    let first = values[0];
    let expected: Vec<u32> = (first..first + values.len() as u32).collect();
    assert_eq!(values, expected, "a value lost, repeated or out of order");
    // The container's own thread (`b/reader`) only sleeps: cycles ran where the
    // values were delivered.
    assert!(
        seen.iter().any(|(_, thread)| thread != "b/reader"),
        "{seen:?}"
    );
}

#[test]
fn in_lockstep_inline_prints_what_park_prints() {
    let registry = registry_with_seq();
    let run = |wait: WaitMode, tag: f64| {
        let peers = two_peers();
        let start = |part: &str| {
            let options = over_zenoh(lockstep(12), "inline_lockstep", part, &peers);
            (parts(&registry, part, tag, wait).start_with(options)).unwrap()
        };
        let (a, b) = (start("a"), start("b"));
        for app in [&a, &b] {
            assert!(
                app.wait_timeout(Duration::from_secs(30)),
                "the run did not end"
            );
            assert_eq!(app.failure(), None);
        }
        drop((a, b));
        lines_of(tag as u64, "b/seq")
    };
    let park = run(WaitMode::Park, 22.0);
    let inline = run(WaitMode::Inline, 23.0);
    assert!(park.len() >= 5, "{park:?}");
    assert_eq!(inline, park);
}
