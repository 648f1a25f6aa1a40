//! The run seed reaches every module's random source, and in lockstep the modules that
//! read the wall clock or the OS's randomness through the runtime are kept (and
//! reported) once each.

use super::*;
use ferroc_module::{ModuleType, Nondeterminism, Out, Random, Timestamp, WallClock};
use std::collections::BTreeMap;
use std::sync::Mutex;

/// The last draw of every `Draws` module, by path.
static LAST: Mutex<BTreeMap<String, u64>> = Mutex::new(BTreeMap::new());
/// One run at a time uses `LAST` (the tests of this file run in parallel).
static ONE_RUN: Mutex<()> = Mutex::new(());

/// Publishes draws of its random source.
struct Draws {
    out: Out<u64>,
    random: Random,
    path: String,
}
impl Module for Draws {
    fn update(&mut self) {
        let x = self.random.next_u64();
        self.out.publish(x);
        LAST.lock().unwrap().insert(self.path.clone(), x);
    }
}
impl ModuleType for Draws {
    const NAME: &'static str = "det.Draws";
    fn create(m: &mut Setup<'_>) -> Self {
        Draws {
            out: m.output("out").build(),
            random: m.random(),
            path: m.path().to_owned(),
        }
    }
}

/// Reads the wall clock every cycle.
struct Stamp {
    out: Out<Timestamp>,
    clock: WallClock,
}
impl Module for Stamp {
    fn update(&mut self) {
        self.out.publish(self.clock.now());
    }
}
impl ModuleType for Stamp {
    const NAME: &'static str = "det.Stamp";
    fn create(m: &mut Setup<'_>) -> Self {
        Stamp {
            out: m.output("out").build(),
            clock: m.wall_clock(),
        }
    }
}

/// Seeds from the OS when created.
struct Entropy {
    out: Out<u64>,
    random: Random,
}
impl Module for Entropy {
    fn update(&mut self) {
        self.out.publish(self.random.next_u64());
    }
}
impl ModuleType for Entropy {
    const NAME: &'static str = "det.Entropy";
    fn create(m: &mut Setup<'_>) -> Self {
        Entropy {
            out: m.output("out").build(),
            random: m.os_random(),
        }
    }
}

fn registry() -> Registry {
    let mut r = Registry::new();
    r.register::<Draws>()
        .register::<Stamp>()
        .register::<Entropy>();
    r
}

fn add(b: &mut Builder<'_>, path: &str, type_name: &str) {
    b.add_module(ModuleSpec {
        path,
        type_name,
        params: &[],
        queues: &[],
        ports: &[],
        violations: Default::default(),
    })
    .unwrap();
}

/// Runs `modules` (path, type) in lockstep for 5 cycles of 10 ms; the builder's run
/// and the last draw of every `Draws` module.
fn run_lockstep(seed: u64, modules: &[(&str, &str)]) -> (Arc<Determinism>, Vec<u64>) {
    let _one = ONE_RUN
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    LAST.lock().unwrap().clear();
    let registry = registry();
    let mut b = Builder::new(&registry);
    b.set_seed(seed);
    for (path, ty) in modules {
        add(&mut b, path, ty);
    }
    b.add_thread(ThreadSpec {
        path: "main".into(),
        schedule: Schedule::Periodic(Duration::from_millis(10)),
        options: ThreadOptions::default(),
        steps: modules
            .iter()
            .map(|(p, _)| (p.to_string(), StepKind::Update))
            .collect(),
    })
    .unwrap();
    let run = Arc::clone(b.run());
    let mut app = b
        .start_with(StartOptions {
            limit: Some(5),
            lockstep: Some(Lockstep::default()),
            network: None,
        })
        .unwrap();
    assert!(app.wait_timeout(Duration::from_secs(120)), "the run ends");
    app.join();
    let last = LAST.lock().unwrap();
    let draws = (modules.iter())
        .filter_map(|(path, _)| last.get(*path).copied())
        .collect();
    (run, draws)
}

#[test]
fn the_run_seed_and_the_path_decide_a_modules_numbers() {
    let modules = [("a/noise", "det.Draws"), ("b/noise", "det.Draws")];
    let (run, first) = run_lockstep(7, &modules);
    let (_, again) = run_lockstep(7, &modules);
    let (_, other) = run_lockstep(8, &modules);
    assert_eq!(first.len(), 2);
    assert_eq!(first, again, "same seed, same numbers");
    assert_ne!(first, other, "another seed, other numbers");
    assert_ne!(first[0], first[1], "two modules, two streams");
    assert_eq!(run.seed(), 7);
    assert!(run.reads().is_empty(), "{:?}", run.reads());
}

#[test]
fn in_lockstep_reads_of_the_wall_clock_and_the_os_are_kept_once_per_module() {
    let modules = [
        ("clock", "det.Stamp"),
        ("entropy", "det.Entropy"),
        ("reads/noise", "det.Draws"),
    ];
    let (run, _) = run_lockstep(1, &modules);
    assert_eq!(
        run.reads(),
        [
            ("entropy".to_owned(), Nondeterminism::OsRandom),
            ("clock".to_owned(), Nondeterminism::WallClock),
        ],
        "the OS's randomness when created, the clock in the first cycle; once each"
    );
}
