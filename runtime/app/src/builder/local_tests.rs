//! Connections the plan marks as inside one thread container (`ConnectOptions::local`):
//! made local at start, refused when their ends are in different containers, and
//! still readable by an inspector while the application runs (the read moves the
//! output to the lock-free path at a cycle boundary).

use super::tests::add;
use super::*;
use crate::inspect::Inspector;
use ferroc_module::{In, ModuleType, Out};
use ferroc_ports::port::{ConnectOptions, CopyInputPort};

/// Publishes 1, 2, 3, … on `output`.
struct Ramp {
    output: Out<f64>,
    n: f64,
}
impl Module for Ramp {
    fn update(&mut self) {
        self.n += 1.0;
        self.output.publish(self.n);
    }
}
impl ModuleType for Ramp {
    const NAME: &'static str = "test.Ramp";
    fn create(m: &mut Setup<'_>) -> Self {
        Ramp {
            output: m.output("output").build(),
            n: 0.0,
        }
    }
}

/// Passes its input on, counting the cycles in which it did not see the ramp's value
/// of the same cycle (the ramp runs first). In its first cycle it also tries to read
/// its input from another thread and publishes on `local` whether that was refused
/// (it is, exactly when the connection is local).
struct Follow {
    input: In<f64>,
    output: Out<f64>,
    missed: Out<f64>,
    local: Out<f64>,
    expected: f64,
    misses: f64,
}
impl Module for Follow {
    fn update(&mut self) {
        if self.expected == 0.0 {
            let input = &self.input;
            let refused = std::thread::scope(|s| s.spawn(|| input.get()).join().is_err());
            self.local.publish(if refused { 1.0 } else { 0.0 });
        }
        self.expected += 1.0;
        let v = self.input.get();
        if v != self.expected || !self.input.changed() {
            self.misses += 1.0;
        }
        self.output.publish(v);
        self.missed.publish(self.misses);
    }
}
impl ModuleType for Follow {
    const NAME: &'static str = "test.Follow";
    fn create(m: &mut Setup<'_>) -> Self {
        Follow {
            input: m.input("input").build(),
            output: m.output("output").build(),
            missed: m.output("missed").build(),
            local: m.output("local").build(),
            expected: 0.0,
            misses: 0.0,
        }
    }
}

fn registry() -> Registry {
    let mut r = Registry::new();
    r.register::<Ramp>().register::<Follow>();
    r
}

fn spec(path: &str, steps: &[&str]) -> ThreadSpec {
    ThreadSpec {
        path: path.into(),
        schedule: Schedule::Periodic(Duration::from_micros(200)),
        options: ThreadOptions::default(),
        steps: steps
            .iter()
            .map(|p| (p.to_string(), StepKind::Update))
            .collect(),
    }
}

fn wired(registry: &Registry, two_containers: bool) -> Builder<'_> {
    wired_with(registry, two_containers, true)
}

fn wired_with(registry: &Registry, two_containers: bool, local: bool) -> Builder<'_> {
    let mut b = Builder::new(registry);
    add(&mut b, "ramp", "test.Ramp", &[]);
    add(&mut b, "follow", "test.Follow", &[]);
    let (from, to) = (("ramp", "output"), ("follow", "input"));
    let options = ConnectOptions::default().with_local(local);
    b.connect(from, to, Conversion::default(), options).unwrap();
    if two_containers {
        b.add_thread(spec("a", &["ramp"])).unwrap();
        b.add_thread(spec("b", &["follow"])).unwrap();
    } else {
        b.add_thread(spec("main", &["ramp", "follow"])).unwrap();
    }
    b
}

/// Runs 20 cycles; (the ramp's last value seen outside, misses, whether the follower's
/// input refused a read from another thread).
fn run_twenty(local: bool) -> (f64, f64, f64) {
    let registry = registry();
    let b = wired_with(&registry, false, local);
    // A reader outside the model, connected before start: the output keeps it current
    // on the lock-free path beside the local reader.
    let probe = CopyInputPort::<f64>::new("probe");
    let missed = CopyInputPort::<f64>::new("missed");
    b.output("ramp", "output")
        .unwrap()
        .connect(&probe.handle(), ConnectOptions::default())
        .unwrap();
    b.output("follow", "missed")
        .unwrap()
        .connect(&missed.handle(), ConnectOptions::default())
        .unwrap();
    let refused = CopyInputPort::<f64>::new("refused");
    b.output("follow", "local")
        .unwrap()
        .connect(&refused.handle(), ConnectOptions::default())
        .unwrap();
    let mut app = b.start(Some(20)).unwrap();
    app.join();
    (probe.get(), missed.get(), refused.get())
}

#[test]
fn a_local_connection_delivers_every_cycle_in_schedule_order() {
    let (ramp, missed, refused) = run_twenty(true);
    assert_eq!(ramp, 20.0);
    assert_eq!(missed, 0.0, "the follower saw each value in its cycle");
    assert_eq!(
        refused, 1.0,
        "the connection is local: other threads are refused"
    );
}

#[test]
fn a_connection_not_marked_local_stays_lock_free() {
    let (ramp, missed, refused) = run_twenty(false);
    assert_eq!((ramp, missed), (20.0, 0.0));
    assert_eq!(refused, 0.0, "lock-free ports may be read from any thread");
}

#[test]
fn a_local_connection_runs_in_lockstep_too() {
    let registry = registry();
    let b = wired(&registry, false);
    let missed = CopyInputPort::<f64>::new("missed");
    b.output("follow", "missed")
        .unwrap()
        .connect(&missed.handle(), ConnectOptions::default())
        .unwrap();
    let options = StartOptions {
        limit: Some(10),
        lockstep: Some(Lockstep {
            periods: vec![Duration::from_micros(200)],
            until: None,
        }),
        network: None,
    };
    crate::test_support::run_to_end(b.start_with(options).unwrap());
    assert_eq!(missed.get(), 0.0);
}

#[test]
fn a_connection_marked_local_across_two_containers_is_refused() {
    let registry = registry();
    let b = wired(&registry, true);
    let err = b.start(Some(1)).map(|_| ()).unwrap_err();
    assert_eq!(
        err.to_string(),
        "`ramp/output` → `follow/input` is marked as inside one thread container, but \
         `ramp` runs in the thread container `a` and `follow` in the thread container `b`; \
         connect it without `ConnectOptions::local`"
    );
}

/// The inspector reads the value of a local output while the container runs: the
/// read is applied at a cycle boundary and moves the output to the lock-free path;
/// the local reader keeps seeing every value in its cycle.
#[test]
fn an_inspector_reads_a_local_output_while_it_runs() {
    let registry = registry();
    let mut b = wired(&registry, false);
    let catalogue = b.inspection();
    let mut app = b.start(None).unwrap();
    let inspector = Inspector::new(catalogue, app.stats(), registry.values());
    // Asked before the first cycle, the output has published nothing yet.
    // Bounded generously: on a loaded machine the container may start late.
    let deadline = std::time::Instant::now() + Duration::from_secs(20);
    while !inspector.value("ramp", "output").unwrap().published {
        assert!(
            std::time::Instant::now() < deadline,
            "the ramp never published"
        );
        std::thread::sleep(Duration::from_millis(1));
    }
    let mut last = 0.0;
    for _ in 0..3 {
        let read = inspector.value("ramp", "output").unwrap();
        assert!(read.published, "{read:?}");
        let v = read.value.as_f64().unwrap();
        assert!(v >= last && v >= 1.0, "read {v} after {last}");
        last = v;
        std::thread::sleep(Duration::from_millis(2));
    }
    let missed = inspector.value("follow", "missed").unwrap();
    assert_eq!(missed.value.as_f64(), Some(0.0), "{missed:?}");
    app.stop();
    app.join();
}
