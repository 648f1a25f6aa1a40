//! Interoperability with an inspection client we did not write: Python's
//! `eclipse-zenoh` (installed by `scripts/test` in a venv) asks a serving program on the
//! documented keys (docs/inspect.md), reads the JSON answers, and cannot change a
//! parameter without the token.
//!
//! The interpreter is `$FERROC_PYTHON`, else the venv `scripts/test` makes
//! (`target/ci-venv`); without one that has `zenoh` the test skips visibly, and fails
//! under FERROC_REQUIRE_ALL=1 (ferroc-testkit).

use ferroc_inspect::server;
use ferroc_runtime::builder::{Builder, ModuleSpec, Registry, Schedule, ThreadSpec};
use ferroc_runtime::builder::{StartOptions, StepKind};
use ferroc_runtime::container::ThreadOptions;
use ferroc_runtime::inspect::view::ParamView;
use ferroc_runtime::inspect::Inspector;
use ferroc_runtime::module::{Module, ModuleType, Out, Parameter, Setup, Value};
use std::path::Path;
use std::process::Command;
use std::sync::Arc;
use std::time::Duration;

struct Gain {
    out: Out<f64>,
    gain: Parameter<f64>,
}
impl Module for Gain {
    fn update(&mut self) {
        let g = self.gain.get();
        self.out.publish(g * 2.0);
    }
}
impl ModuleType for Gain {
    const NAME: &'static str = "test.Gain";
    fn create(m: &mut Setup<'_>) -> Self {
        Gain {
            out: m.output("out").build(),
            gain: m.param("gain").range(0.0, 5.0).default(0.25).build(),
        }
    }
}

#[test]
fn a_python_zenoh_client_reads_answers_and_cannot_change_without_the_token() {
    let Some(python) = ferroc_testkit::python(&["zenoh"]) else {
        return;
    };
    let mut registry = Registry::new();
    registry.register::<Gain>();
    let mut b = Builder::new(&registry);
    b.add_module(ModuleSpec {
        path: "robot/gain",
        type_name: "test.Gain",
        params: &[],
        queues: &[],
        ports: &[],
        violations: Default::default(),
    })
    .unwrap();
    b.add_thread(ThreadSpec {
        path: "robot/main".into(),
        schedule: Schedule::Periodic(Duration::from_millis(20)),
        options: ThreadOptions::default(),
        steps: vec![("robot/gain".into(), StepKind::Update)],
    })
    .unwrap();
    let catalogue = b.inspection();
    // Free-running: the Python client sees a live program.
    let app = b.start_with(StartOptions::default()).unwrap();
    let inspector = Inspector::new(catalogue, app.stats(), registry.values());
    let port = ferroc_testkit::free_port();
    let config = ferroc_inspect::config::server(&format!("127.0.0.1:{port}")).unwrap();
    let parse = Box::new(|_: &ParamView, t: &str| {
        t.parse::<f64>()
            .map(Value::Float)
            .map_err(|e| e.to_string())
    });
    let _server = server::serve(
        config,
        "py",
        Arc::new(inspector),
        "secret-token".into(),
        parse,
    )
    .unwrap();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/python/inspect_client.py");
    let out = Command::new(python)
        .arg(script)
        .args([
            &format!("tcp/127.0.0.1:{port}"),
            "py",
            "robot",
            "robot/gain/out",
            "robot/gain/gain",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(r["tree"][0]["key"], "ferroc/py/inspect/robot/tree");
    assert_eq!(r["tree"][0]["ok"]["modules"][0]["type"], "test.Gain");
    assert_eq!(r["value"][0]["ok"]["value"], 0.5, "{r}");
    assert_eq!(r["param"][0]["ok"]["value"], "0.25");
    let refused = r["refused"][0]["err"]["error"].as_str().unwrap_or_default();
    assert!(refused.contains("not authorised"), "{r}");
    assert_eq!(r["after"][0]["ok"]["value"], "0.25", "nothing changed");
    drop(app);
}
