// A scenario reads as one story from start to end; the function-length rule is for
// the code under test.
#![allow(clippy::too_many_lines)]
use super::*;
use crate::builder::{
    Builder, Conversion, Lockstep, ModuleSpec, Registry, RunningApp, Schedule, StartOptions,
    StepKind, ThreadSpec,
};
use ferroc_exec::ThreadOptions;
use ferroc_module::{In, Module, ModuleType, Out, Parameter, Setup, Value};
use ferroc_ports::port::{ConnectOptions, CopyInputPort};
use std::time::{Duration, Instant};

struct Source {
    out: Out<f64>,
    value: Parameter<f64>,
}
impl Module for Source {
    fn update(&mut self) {
        self.out.publish(self.value.get());
    }
}
impl ModuleType for Source {
    const NAME: &'static str = "t.Source";
    fn create(m: &mut Setup<'_>) -> Self {
        Source {
            out: m.output("out").build(),
            value: m.param("value").default(1.0).build(),
        }
    }
}

struct Times {
    input: In<f64>,
    output: Out<f64>,
    factor: Parameter<f64>,
}
impl Module for Times {
    fn update(&mut self) {
        self.output.publish(self.input.get() * self.factor.get());
    }
}
impl ModuleType for Times {
    const NAME: &'static str = "t.Times";
    fn create(m: &mut Setup<'_>) -> Self {
        Times {
            input: m.input("input").build(),
            output: m.output("output").build(),
            factor: m.param("factor").default(1.0).build(),
        }
    }
}

fn spec<'a>(path: &'a str, ty: &'a str, params: &'a [(String, Value)]) -> ModuleSpec<'a> {
    ModuleSpec {
        path,
        type_name: ty,
        params,
        queues: &[],
        ports: &[],
        violations: Default::default(),
    }
}

fn thread(path: &str, steps: &[&str]) -> ThreadSpec {
    ThreadSpec {
        path: path.into(),
        schedule: Schedule::Periodic(Duration::from_millis(1)),
        options: ThreadOptions::default(),
        steps: steps
            .iter()
            .map(|p| (p.to_string(), StepKind::Update))
            .collect(),
    }
}

fn steps(paths: &[&str]) -> Vec<(String, StepKind)> {
    paths
        .iter()
        .map(|p| (p.to_string(), StepKind::Update))
        .collect()
}

fn port(m: &str, p: &str) -> PortPath {
    (m.into(), p.into())
}

/// Waits (bounded, generously: a loaded machine) until `probe` reads `want`.
fn until(probe: &CopyInputPort<f64>, want: f64) {
    let deadline = Instant::now() + Duration::from_secs(20);
    while probe.get() != want {
        assert!(
            Instant::now() < deadline,
            "still {} instead of {want}",
            probe.get()
        );
        std::thread::sleep(Duration::from_millis(1));
    }
}

/// Waits (bounded) until the container `i` has run more cycles than `than`.
fn rises(app: &RunningApp, i: usize, than: u64) -> u64 {
    let deadline = Instant::now() + Duration::from_secs(20);
    loop {
        let now = app.status()[i].cycles;
        if now > than {
            return now;
        }
        assert!(Instant::now() < deadline, "container {i} stopped cycling");
        std::thread::sleep(Duration::from_millis(1));
    }
}

#[test]
fn modules_are_inserted_moved_and_removed_while_the_others_keep_cycling() {
    let mut registry = Registry::new();
    registry.register::<Source>().register::<Times>();
    let mut b = Builder::new(&registry);
    let four = [("value".to_string(), Value::Float(4.0))];
    let two = [("factor".to_string(), Value::Float(2.0))];
    b.add_module(spec("p/a/src", "t.Source", &four)).unwrap();
    b.add_module(spec("p/a/g1", "t.Times", &two)).unwrap();
    b.add_module(spec("p/b/other", "t.Source", &[])).unwrap();
    b.connect(
        ("p/a/src", "out"),
        ("p/a/g1", "input"),
        Conversion::default(),
        ConnectOptions::default(),
    )
    .unwrap();
    let probe = CopyInputPort::<f64>::new("probe");
    b.output("p/a/g1", "output")
        .unwrap()
        .connect(&probe.handle(), ConnectOptions::default())
        .unwrap();
    b.add_thread(thread("p/a", &["p/a/src", "p/a/g1"])).unwrap();
    b.add_thread(thread("p/b", &["p/b/other"])).unwrap();
    let catalogue = b.inspection();
    assert_eq!(catalogue.modules.len(), 3);
    let (app, mut live) = b.start_live(StartOptions::default()).unwrap();
    until(&probe, 8.0);

    // Insert g2 (× 3) between src and g1, in p/a.
    let three = [("factor".to_string(), Value::Float(3.0))];
    let before = rises(&app, 1, 0);
    let done = live
        .apply(Reconfiguration {
            add: vec![spec("p/a/g2", "t.Times", &three)],
            disconnect: vec![(port("p/a/src", "out"), port("p/a/g1", "input"))],
            connect: vec![
                (port("p/a/src", "out"), port("p/a/g2", "input")),
                (port("p/a/g2", "output"), port("p/a/g1", "input")),
            ],
            threads: vec![("p/a".into(), steps(&["p/a/src", "p/a/g2", "p/a/g1"]))],
            ..Default::default()
        })
        .unwrap();
    assert!(
        done.iter().any(|l| l.contains("`p/a` switched")),
        "{done:?}"
    );
    assert!(
        !done.iter().any(|l| l.contains("p/b")),
        "p/b is not touched: {done:?}"
    );
    until(&probe, 24.0);
    rises(&app, 1, before);
    let paths: Vec<String> = live
        .catalogue()
        .modules
        .into_iter()
        .map(|m| m.path)
        .collect();
    assert_eq!(
        paths,
        ["p/a/src", "p/a/g1", "p/b/other", "p/a/g2"],
        "added last"
    );

    // A change that cannot be made changes nothing.
    let e = live
        .apply(Reconfiguration {
            remove: vec!["p/a/g2".into()],
            connect: vec![(port("p/a/src", "nope"), port("p/a/g1", "input"))],
            threads: vec![("p/a".into(), steps(&["p/a/src", "p/a/g1"]))],
            ..Default::default()
        })
        .unwrap_err();
    assert!(e.contains("`p/a/src` has no output `nope`"), "{e}");
    let e = live
        .apply(Reconfiguration {
            add: vec![spec("p/a/g3", "t.Missing", &[])],
            ..Default::default()
        })
        .unwrap_err();
    assert!(e.contains("not registered"), "{e}");
    std::thread::sleep(Duration::from_millis(20));
    assert_eq!(probe.get(), 24.0);

    // Move g2 to p/b: same instance, its connections stay; p/a keeps cycling.
    let a_before = app.status()[0].cycles;
    live.apply(Reconfiguration {
        moves: vec![("p/a/g2".into(), "p/b/g2".into())],
        threads: vec![
            ("p/a".into(), steps(&["p/a/src", "p/a/g1"])),
            ("p/b".into(), steps(&["p/b/other", "p/b/g2"])),
        ],
        params: vec![("p/b/g2".into(), "factor".into(), Value::Float(5.0))],
        ..Default::default()
    })
    .unwrap();
    until(&probe, 40.0);
    rises(&app, 0, a_before);
    let tree = live.catalogue();
    let (_, in_b) = tree.threads.iter().find(|(p, _)| p == "p/b").unwrap();
    assert_eq!(in_b, &["p/b/other", "p/b/g2"]);

    // Remove it again and reconnect.
    live.apply(Reconfiguration {
        remove: vec!["p/b/g2".into()],
        disconnect: vec![
            (port("p/a/src", "out"), port("p/b/g2", "input")),
            (port("p/b/g2", "output"), port("p/a/g1", "input")),
        ],
        connect: vec![(port("p/a/src", "out"), port("p/a/g1", "input"))],
        threads: vec![("p/b".into(), steps(&["p/b/other"]))],
        ..Default::default()
    })
    .unwrap();
    until(&probe, 8.0);
    assert_eq!(live.catalogue().modules.len(), 3);
    drop(app);
}

#[test]
fn a_data_triggered_container_switches_too_and_wakes_for_a_new_module() {
    let mut registry = Registry::new();
    registry.register::<Source>().register::<Times>();
    let mut b = Builder::new(&registry);
    let four = [("value".to_string(), Value::Float(4.0))];
    b.add_module(spec("p/a/src", "t.Source", &four)).unwrap();
    b.add_module(spec("p/d/g1", "t.Times", &[])).unwrap();
    b.connect(
        ("p/a/src", "out"),
        ("p/d/g1", "input"),
        Conversion::default(),
        ConnectOptions::default(),
    )
    .unwrap();
    b.add_thread(thread("p/a", &["p/a/src"])).unwrap();
    b.add_thread(ThreadSpec {
        schedule: Schedule::Data,
        ..thread("p/d", &["p/d/g1"])
    })
    .unwrap();
    let (app, mut live) = b.start_live(StartOptions::default()).unwrap();
    rises(&app, 1, 0);
    // A second reader in the data-triggered container, fed from p/a.
    let ten = [("factor".to_string(), Value::Float(10.0))];
    let done = live
        .apply(Reconfiguration {
            add: vec![spec("p/d/g2", "t.Times", &ten)],
            connect: vec![(port("p/a/src", "out"), port("p/d/g2", "input"))],
            threads: vec![("p/d".into(), steps(&["p/d/g1", "p/d/g2"]))],
            ..Default::default()
        })
        .unwrap();
    assert!(
        done.iter().any(|l| l.contains("`p/d` switched")),
        "{done:?}"
    );
    let probe = CopyInputPort::<f64>::new("probe");
    let catalogue = live.catalogue();
    let g2 = catalogue
        .modules
        .iter()
        .find(|m| m.path == "p/d/g2")
        .unwrap();
    let (_, out) = g2.outputs.iter().find(|(n, _)| n == "output").unwrap();
    out.connect(&probe.handle(), ConnectOptions::default())
        .unwrap();
    until(&probe, 40.0);
    let before = app.status()[1].cycles;
    rises(&app, 1, before);
    drop(app);
}

#[test]
fn a_lockstep_run_takes_no_change() {
    let mut registry = Registry::new();
    registry.register::<Source>().register::<Times>();
    let mut b = Builder::new(&registry);
    b.add_module(spec("p/a/src", "t.Source", &[])).unwrap();
    b.add_thread(thread("p/a", &["p/a/src"])).unwrap();
    let options = StartOptions {
        limit: Some(3),
        lockstep: Some(Lockstep {
            periods: Vec::new(),
            until: None,
        }),
        network: None,
    };
    let (mut app, mut live) = b.start_live(options).unwrap();
    let e = live
        .apply(Reconfiguration {
            remove: vec!["p/a/src".into()],
            threads: vec![("p/a".into(), Vec::new())],
            ..Default::default()
        })
        .unwrap_err();
    assert!(e.contains("lockstep"), "{e}");
    app.join();
    assert_eq!(app.status()[0].cycles, 3, "the run is not touched");
}
