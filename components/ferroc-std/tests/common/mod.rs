//! What the application tests of ferroc_std share: an application of one thread
//! container built by hand with the runtime's `Builder`, run for a number of cycles.
//! Each test file uses part of it.
#![allow(dead_code)]

use ferroc_runtime::behaviour::ViolationPolicy;
use ferroc_runtime::builder::{
    BuildError, Builder, Lockstep, ModuleSpec, Registry, RunningApp, Schedule, StartOptions,
    StepKind, ThreadSpec,
};
use ferroc_runtime::container::ThreadOptions;
use ferroc_runtime::module::{PortGroup, Value};
use ferroc_runtime::port::ConnectOptions;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// A registry with ferroc_std's module types.
pub fn registry() -> Registry {
    let mut r = Registry::new();
    ferroc_std::register(&mut r);
    r
}

/// Adds a module with parameters and instance-declared port groups.
pub fn add(
    b: &mut Builder<'_>,
    path: &str,
    ty: &str,
    params: &[(&str, Value)],
    ports: &[PortGroup<'_>],
) -> Result<(), BuildError> {
    let params: Vec<(String, Value)> = params
        .iter()
        .map(|(n, v)| (n.to_string(), v.clone()))
        .collect();
    b.add_module(ModuleSpec {
        path,
        type_name: ty,
        params: &params,
        queues: &[],
        ports,
        violations: ViolationPolicy::Warn,
    })
}

/// Connects an output to an input without conversion.
pub fn wire(b: &mut Builder<'_>, from: (&str, &str), to: (&str, &str)) {
    b.connect(from, to, Default::default(), ConnectOptions::default())
        .unwrap();
}

/// An empty folder of this name below the test's scratch directory.
///
/// Loggers write only inside the log folder: it is the scratch directory.
pub fn scratch(name: &str) -> PathBuf {
    ferroc_std::recording::set_log_dir(Some(env!("CARGO_TARGET_TMPDIR").into()));
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The thread container `main` of the application: `steps` in this order, every
/// `period`.
fn main_container(b: &mut Builder<'_>, steps: &[&str], period: Duration) {
    b.add_thread(ThreadSpec {
        path: "main".into(),
        schedule: Schedule::Periodic(period),
        options: ThreadOptions::default(),
        steps: steps
            .iter()
            .map(|p| (p.to_string(), StepKind::Update))
            .collect(),
    })
    .unwrap();
}

/// Runs `steps` in one container of 10 ms in lockstep (model time) for `cycles`
/// cycles; no module may panic. The application is gone on return, so files its
/// modules wrote are complete.
pub fn run_lockstep(mut b: Builder<'_>, steps: &[&str], cycles: u64) {
    main_container(&mut b, steps, Duration::from_millis(10));
    let mut app = b
        .start_with(StartOptions {
            limit: Some(cycles),
            lockstep: Some(Lockstep::default()),
            network: None,
        })
        .unwrap();
    app.join();
    assert!(app.panics().is_empty(), "{:?}", app.panics());
}

/// Runs `steps` freely in one container of `period` for `cycles` cycles and returns
/// the ended application (for its statistics and panics).
pub fn run_free(mut b: Builder<'_>, steps: &[&str], period: Duration, cycles: u64) -> RunningApp {
    main_container(&mut b, steps, period);
    let mut app = b.start(Some(cycles)).unwrap();
    app.join();
    app
}
