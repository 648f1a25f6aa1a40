//! A stop request ends a run however its containers are waiting: a write blocked on a
//! full queue nobody drains, a sleep until a deadline an hour away. A step that never
//! returns is left behind and named, instead of hanging the caller.

use super::*;
use ferroc_exec::Trigger;
use ferroc_module::{In, ModuleType, Out};
use ferroc_ports::port::{ConnectOptions, OnFull, QueueConfig};
use std::sync::atomic::{AtomicBool, Ordering};

struct Counter {
    out: Out<f64>,
    n: f64,
}
impl Module for Counter {
    fn update(&mut self) {
        self.n += 1.0;
        self.out.publish(self.n);
    }
}
impl ModuleType for Counter {
    const NAME: &'static str = "stop.Counter";
    fn create(m: &mut Setup<'_>) -> Self {
        Counter {
            out: m.output("out").build(),
            n: 0.0,
        }
    }
}

/// Reads the latest value only: a queue on its input is never drained.
struct Latest {
    input: In<f64>,
    seen: f64,
}
impl Module for Latest {
    fn update(&mut self) {
        self.seen = self.input.get();
    }
}
impl ModuleType for Latest {
    const NAME: &'static str = "stop.Latest";
    fn create(m: &mut Setup<'_>) -> Self {
        Latest {
            input: m.input("input").build(),
            seen: 0.0,
        }
    }
}

/// Never returns from its step until the test releases it.
static RELEASE: AtomicBool = AtomicBool::new(false);
static ENTERED: AtomicBool = AtomicBool::new(false);
struct Stuck;
impl Module for Stuck {
    fn update(&mut self) {
        ENTERED.store(true, Ordering::SeqCst);
        while !RELEASE.load(Ordering::Relaxed) {
            std::thread::sleep(Duration::from_millis(5));
        }
    }
}
impl ModuleType for Stuck {
    const NAME: &'static str = "stop.Stuck";
    fn create(_: &mut Setup<'_>) -> Self {
        Stuck
    }
}

fn registry() -> Registry {
    let mut r = Registry::new();
    r.register::<Counter>()
        .register::<Latest>()
        .register::<Stuck>();
    r
}

fn module(b: &mut Builder<'_>, path: &str, type_name: &str, queues: &[(String, QueueConfig)]) {
    b.add_module(ModuleSpec {
        path,
        type_name,
        params: &[],
        queues,
        ports: &[],
        violations: Default::default(),
    })
    .unwrap();
}

fn thread(path: &str, period: Duration, steps: &[&str]) -> ThreadSpec {
    ThreadSpec {
        path: path.into(),
        schedule: Schedule::Periodic(period),
        options: ThreadOptions::default(),
        steps: steps
            .iter()
            .map(|p| (p.to_string(), StepKind::Update))
            .collect(),
    }
}

/// Waits (bounded) until the container has run `n` cycles.
fn wait_for_cycles(app: &RunningApp, n: u64) {
    for _ in 0..60_000 {
        if app.status()[0].cycles >= n {
            return;
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    panic!("the container never ran {n} cycles");
}

/// `queue="1" on-full="block"` into a module of the same container that never pops:
/// the second write waits for room that never comes. Before the fix the run ignored
/// every stop request from then on.
#[test]
fn a_write_blocked_on_a_queue_nobody_drains_ends_when_the_run_stops() {
    let registry = registry();
    let mut b = Builder::new(&registry);
    module(&mut b, "p/t/c", "stop.Counter", &[]);
    let queue = QueueConfig::new(1).on_full(OnFull::Block);
    module(&mut b, "p/t/s", "stop.Latest", &[("input".into(), queue)]);
    b.connect(
        ("p/t/c", "out"),
        ("p/t/s", "input"),
        Conversion::default(),
        ConnectOptions::default(),
    )
    .unwrap();
    b.add_thread(thread("p/t", Duration::from_millis(1), &["p/t/c", "p/t/s"]))
        .unwrap();
    let mut app = b.start(None).unwrap();
    // The first cycle fills the queue; the second blocks in its first step.
    wait_for_cycles(&app, 1);
    std::thread::sleep(Duration::from_millis(50));
    assert_eq!(app.status()[0].cycles, 1, "the second cycle waits for room");
    app.stop();
    let stuck = app.join_within(Duration::from_secs(60));
    assert!(stuck.is_empty(), "still running after the stop: {stuck:?}");
}

/// A periodic container sleeping until a deadline an hour away stops at once.
#[test]
fn a_container_with_a_long_period_stops_without_waiting_for_its_next_deadline() {
    let registry = registry();
    let mut b = Builder::new(&registry);
    module(&mut b, "p/slow/c", "stop.Counter", &[]);
    b.add_thread(thread("p/slow", Duration::from_secs(3600), &["p/slow/c"]))
        .unwrap();
    let mut app = b.start(None).unwrap();
    wait_for_cycles(&app, 1);
    app.stop();
    let stuck = app.join_within(Duration::from_secs(60));
    assert!(stuck.is_empty(), "still sleeping after the stop: {stuck:?}");
    assert_eq!(app.status()[0].cycles, 1);
}

/// A step that never returns cannot be interrupted; the container is named and left
/// behind so that the caller can exit.
#[test]
fn a_step_that_never_returns_is_named_and_left_behind() {
    let registry = registry();
    let mut b = Builder::new(&registry);
    module(&mut b, "p/t/stuck", "stop.Stuck", &[]);
    b.add_thread(thread("p/t", Duration::from_millis(1), &["p/t/stuck"]))
        .unwrap();
    let mut app = b.start(None).unwrap();
    // Bounded wait until the step is inside its loop (however slow the machine).
    for _ in 0..60_000 {
        if ENTERED.load(Ordering::SeqCst) {
            break;
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    assert!(ENTERED.load(Ordering::SeqCst), "the step never started");
    app.stop();
    let stuck = app.join_within(Duration::from_millis(200));
    RELEASE.store(true, Ordering::Relaxed);
    assert_eq!(stuck, ["p/t"]);
}

/// `--cycles N` is N cycles of the application's fastest periodic containers: with a
/// 25 ms, a 1 s and a 40 ms container and N = 80, the 25 ms one runs 80 and ends the
/// run, the others run until then (not 80 each, which kept the 1 s one running for 78 s
/// after the fast one stopped).
#[test]
fn the_cycle_limit_counts_cycles_of_the_application() {
    let ms = Duration::from_millis;
    let data = Trigger::Data(ferroc_ports::port::Wakeup::new());
    let mixed = [
        Trigger::Periodic(ms(25)),
        Trigger::Periodic(ms(1000)),
        Trigger::Periodic(ms(40)),
        Trigger::Continuous,
        data.clone(),
    ];
    assert_eq!(
        cycles_of(&mixed, Some(80)),
        [
            (Some(80), true),
            (None, false),
            (None, false),
            (None, false),
            (None, false)
        ]
    );
    assert_eq!(cycles_of(&mixed, None)[0], (None, true));
    // Without periodic containers: continuous ones count, else data-triggered ones.
    let unclocked = [Trigger::Continuous, data.clone()];
    assert_eq!(
        cycles_of(&unclocked, Some(5)),
        [(Some(5), true), (None, false)]
    );
    assert_eq!(cycles_of(&[data], Some(5)), [(Some(5), true)]);
}

/// Free-running, a slow container stops with the fast one, having run about its
/// share (its exact count depends on the machine; in lockstep it is exact).
#[test]
fn a_slow_container_stops_with_the_fast_one() {
    let registry = registry();
    let mut b = Builder::new(&registry);
    module(&mut b, "p/fast/c", "stop.Counter", &[]);
    module(&mut b, "p/slow/c", "stop.Counter", &[]);
    b.add_thread(thread("p/fast", Duration::from_millis(2), &["p/fast/c"]))
        .unwrap();
    b.add_thread(thread("p/slow", Duration::from_secs(3600), &["p/slow/c"]))
        .unwrap();
    let mut app = b.start(Some(10)).unwrap();
    assert!(app.wait_timeout(Duration::from_secs(120)), "the run ends");
    app.stop();
    assert!(app.join_within(Duration::from_secs(60)).is_empty());
    let cycles: Vec<u64> = app.status().iter().map(|s| s.cycles).collect();
    assert_eq!(
        cycles,
        [10, 1],
        "the hourly container ran its first cycle only"
    );
}

/// In lockstep the limit is exact: the instants before N times the shortest period.
#[test]
fn in_lockstep_each_container_runs_the_instants_before_the_end() {
    let registry = registry();
    let mut b = Builder::new(&registry);
    module(&mut b, "p/fast/c", "stop.Counter", &[]);
    module(&mut b, "p/slow/c", "stop.Counter", &[]);
    b.add_thread(thread("p/fast", Duration::from_millis(2), &["p/fast/c"]))
        .unwrap();
    b.add_thread(thread("p/slow", Duration::from_millis(8), &["p/slow/c"]))
        .unwrap();
    let options = StartOptions {
        limit: Some(10),
        lockstep: Some(Lockstep::default()),
        network: None,
    };
    let mut app = b.start_with(options).unwrap();
    assert!(app.wait_timeout(Duration::from_secs(120)), "the run ends");
    app.join();
    let cycles: Vec<u64> = app.status().iter().map(|s| s.cycles).collect();
    assert_eq!(cycles, [10, 3], "before 20 ms: 0, 8 and 16 ms");
}
