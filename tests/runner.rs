//! `ferroc run` and `ferroc types` for a library written outside ferroc: its crate is
//! built into a runner once, a changed model rebuilds nothing, a changed crate rebuilds,
//! and every way the crate can be wrong is reported at its manifest.

mod common;

use common::tempdir;
use std::path::{Path, PathBuf};
use std::process::Command;

/// This test run's target folder (runners share it with the checkout's crates).
fn target() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    exe.ancestors().nth(3).unwrap().to_path_buf()
}

/// `ferroc ARGS` in `dir`, building runners in this test run's target folder.
fn ferroc_in(dir: &Path, args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_ferroc"))
        .args(args)
        .current_dir(dir)
        .env("CARGO_TARGET_DIR", target())
        .output()
        .expect("ferroc runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

const MANIFEST: &str = r#"<library name="beep" version="0.1.0" rust-crate="beep-lib">
  <module-type name="Counter" rust="beep::Counter" doc="counts in steps">
    <out name="count" type="f64" unit="m"/>
    <param name="step" type="f64" default="1"/>
  </module-type>
</library>
"#;

const LIB: &str = r#"use ferroc_runtime::builder::Registry;
use ferroc_runtime::module::{Module, ModuleType, Out, Parameter, Setup};

pub struct Counter { out: Out<f64>, step: Parameter<f64>, n: f64 }

impl ModuleType for Counter {
    const NAME: &'static str = "beep.Counter";
    const DOC: &'static str = "counts in steps";
    fn create(m: &mut Setup<'_>) -> Self {
        Counter { out: m.output("count").unit("m").build(), step: m.param("step").default(1.0).build(), n: 0.0 }
    }
}

impl Module for Counter {
    fn update(&mut self) {
        self.n += self.step.get();
        self.out.publish(self.n);
        println!("beep {}", self.n);
    }
}

pub fn register(registry: &mut Registry) {
    registry.register::<Counter>();
}
"#;

fn model(step: &str) -> String {
    format!(
        r#"<application name="beeper" version="1">
  <use library="beep" manifest="beep.lib.xml"/>
  <part name="p"><thread name="t" period="10ms">
    <module name="c" type="beep.Counter"><param name="step">{step}</param></module>
  </thread></part>
</application>
"#
    )
}

/// A crate of its own in `dir`: Cargo.toml (the runtime by path), manifest, code, model.
fn write_library(dir: &Path, package: &str, lib: &str) {
    common::write_library_toml(dir, package, "beep");
    std::fs::write(
        dir.join("beep.lib.xml"),
        MANIFEST.replace("beep-lib", package),
    )
    .unwrap();
    std::fs::write(dir.join("src/lib.rs"), lib).unwrap();
    std::fs::write(dir.join("beeper.xml"), model("1")).unwrap();
}

/// The (plain) runner executable whose generated main.rs links the library from `dir`.
fn runner_of(dir: &Path) -> PathBuf {
    let dir = dir.canonicalize().unwrap();
    let generated = target().join("ferroc-runner");
    for entry in std::fs::read_dir(&generated).unwrap() {
        let package = entry.unwrap().path();
        let toml = std::fs::read_to_string(package.join("Cargo.toml")).unwrap_or_default();
        if toml.contains(&format!("path = {:?}", dir.to_str().unwrap()))
            && toml.contains("ferroc-runner = { path = ")
        {
            let key = package.file_name().unwrap().to_str().unwrap().to_string();
            return target().join("debug").join(format!("ferroc-runner-{key}"));
        }
    }
    panic!("no runner links {}", dir.display());
}

/// The runner refuses a plan of another layout and ferroc with what to do, and
/// deletes it; without a plan it says what it is.
fn a_plan_of_another_version_is_refused(exe: &Path, dir: &Path) {
    let plan = dir.join("old-plan.json");
    std::fs::write(
        &plan,
        r#"{"format":"ferroc-run-plan","version":999,"ferroc":"9.9.9","modules":[]}"#,
    )
    .unwrap();
    let out = Command::new(exe)
        .args(["run", "--plan"])
        .arg(&plan)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("layout version 999 (written by ferroc 9.9.9); this runner reads version 1"),
        "{err}"
    );
    assert!(
        err.contains("help: run the model with `ferroc run`"),
        "{err}"
    );
    assert!(!plan.exists(), "the refused plan is left behind");
    let out = Command::new(exe).arg("beeper.xml").output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("this program is a ferroc runner"), "{err}");
}

fn modified(path: &Path) -> std::time::SystemTime {
    std::fs::metadata(path).unwrap().modified().unwrap()
}

#[test]
fn a_library_written_outside_ferroc_runs_checks_and_rebuilds_only_when_its_crate_changes() {
    let dir = tempdir("runner_beep");
    write_library(&dir, "beep-lib", LIB);
    let run = ["run", "beeper.xml", "--lockstep", "--cycles", "3", "-q"];

    let (code, out, err) = ferroc_in(&dir, &run);
    assert_eq!(code, 0, "{err}");
    assert_eq!(out, "beep 1\nbeep 2\nbeep 3\n", "{err}");
    assert!(err.contains("p/t: 3 cycles"), "{err}");
    let exe = runner_of(&dir);
    let built = modified(&exe);
    a_plan_of_another_version_is_refused(&exe, &dir);

    let (code, _, err) = ferroc_in(&dir, &["types", "export", "--check", "--lib-path", "."]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("1 module type in 1 library agree"), "{err}");

    // A changed model: the same runner, nothing built.
    std::fs::write(dir.join("beeper.xml"), model("2.5")).unwrap();
    let (code, out, err) = ferroc_in(&dir, &run);
    assert_eq!(code, 0, "{err}");
    assert_eq!(out, "beep 2.5\nbeep 5\nbeep 7.5\n");
    assert!(
        !err.contains("Compiling") && !err.contains("building"),
        "{err}"
    );
    assert_eq!(
        modified(&exe),
        built,
        "the runner was rebuilt for a model change"
    );

    // A manifest that no longer says what the code does: refused at the manifest,
    // by `run` and by `types export --check`, still without a rebuild.
    let drifted = MANIFEST.replace(r#"unit="m""#, r#"unit="s""#);
    std::fs::write(dir.join("beep.lib.xml"), &drifted).unwrap();
    let (code, out, err) = ferroc_in(&dir, &run);
    assert_eq!(code, 1, "{out}{err}");
    assert!(
        err.contains("beep.lib.xml:2:22: error: the Rust type `beep::Counter` does not implement the interface its manifest declares for `beep.Counter`"),
        "{err}"
    );
    assert!(
        err.contains("port `count`: the manifest says unit `s`, the code `m`"),
        "{err}"
    );
    let (code, _, err) = ferroc_in(&dir, &["types", "export", "--check", "--lib-path", "."]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("beep.lib.xml:2:22: error: the manifest of `beep.Counter` differs"),
        "{err}"
    );
    assert_eq!(modified(&exe), built);

    // A module type the manifest declares and the crate does not register.
    let extra = MANIFEST.replace(
        "</library>",
        "  <module-type name=\"Silent\" rust=\"beep::Silent\"/>\n</library>",
    );
    std::fs::write(dir.join("beep.lib.xml"), extra).unwrap();
    std::fs::write(
        dir.join("silent.xml"),
        model("1").replace(
            "</thread>",
            "<module name=\"s\" type=\"beep.Silent\"/></thread>",
        ),
    )
    .unwrap();
    let (code, out, err) = ferroc_in(&dir, &["run", "silent.xml", "--cycles", "1"]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(
        err.contains("error: the module type `beep.Silent` of `p/t/s` is not registered by the crate `beep-lib` of library `beep` (beep.lib.xml:1:16)"),
        "{err}"
    );
    assert!(
        err.contains("help: its `register` function must call `registry.register::<beep::Silent>()`; it registers beep.Counter"),
        "{err}"
    );
    assert_eq!(modified(&exe), built);
    std::fs::write(dir.join("beep.lib.xml"), MANIFEST).unwrap();

    // A changed crate: rebuilt (the library and the runner only), and the change runs.
    std::fs::write(dir.join("src/lib.rs"), LIB.replace("beep {}", "boop {}")).unwrap();
    // (-v: cargo's own lines, which say what was compiled)
    let verbose: Vec<&str> = run.iter().copied().chain(["-v"]).collect();
    let (code, out, err) = ferroc_in(&dir, &verbose);
    assert_eq!(code, 0, "{err}");
    assert_eq!(out, "boop 2.5\nboop 5\nboop 7.5\n");
    assert!(err.contains("Compiling beep-lib"), "{err}");
    assert!(!err.contains("Compiling ferroc-runtime"), "{err}");

    // A crate that does not build: cargo's error, then the manifest it belongs to.
    std::fs::write(
        dir.join("src/lib.rs"),
        LIB.replace("self.n += ", "self.n += true + "),
    )
    .unwrap();
    let (code, out, err) = ferroc_in(&dir, &run);
    assert_eq!(code, 1, "{out}{err}");
    assert!(err.contains("error[E0"), "cargo's error is shown: {err}");
    assert!(
        err.contains("beep.lib.xml:1:16: error: the crate `beep-lib` of library `beep` does not build (cargo's errors above)"),
        "{err}"
    );
    assert!(out.is_empty(), "{out}");
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn a_missing_crate_or_a_crate_without_register_is_reported_at_the_manifest() {
    let dir = tempdir("runner_missing");
    write_library(&dir, "beep-lib", LIB);
    std::fs::write(
        dir.join("beep.lib.xml"),
        MANIFEST.replace(r#"rust-crate="beep-lib""#, r#"rust-crate="beep-nowhere""#),
    )
    .unwrap();
    let (code, _, err) = ferroc_in(&dir, &["run", "beeper.xml", "--cycles", "1"]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains(
            "beep.lib.xml:1:16: error: the crate `beep-nowhere` of library `beep` was not found"
        ),
        "{err}"
    );
    assert!(
        err.contains("found other packages"),
        "names the package it did find: {err}"
    );
    assert!(!err.contains("Compiling"), "nothing is built: {err}");
    let (code, _, err) = ferroc_in(&dir, &["types", "list", "--lib-path", "."]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("was not found"), "{err}");

    // The crate is there but has no `register`: the runner cannot call it.
    let dir = tempdir("runner_unregistered");
    write_library(
        &dir,
        "beep-silent",
        &LIB.replace("pub fn register", "pub fn enroll"),
    );
    let (code, _, err) = ferroc_in(&dir, &["run", "beeper.xml", "--cycles", "1"]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("beep.lib.xml:1:16: error: the runner could not call `beep-silent::register` of library `beep`"),
        "{err}"
    );
    assert!(err.contains("must have `pub fn register("), "{err}");
}

#[test]
fn the_scaffold_checks_runs_tests_and_agrees_with_its_manifest() {
    let dir = tempdir("runner_new");
    let (code, _, err) = ferroc_in(&dir, &["new", "library", "hello_bot"]);
    assert_eq!(code, 0, "{err}");
    for file in ["Cargo.toml", "hello_bot.lib.xml", "src/lib.rs", "demo.xml"] {
        assert!(dir.join("hello_bot").join(file).is_file(), "{file} written");
    }
    let (code, out, err) = ferroc_in(&dir, &["check", "hello_bot/demo.xml"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("0 error(s), 0 warning(s)"), "{out}");
    let (code, out, err) = ferroc_in(
        &dir,
        &[
            "run",
            "hello_bot/demo.xml",
            "--lockstep",
            "--cycles",
            "3",
            "-q",
        ],
    );
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        out,
        "[hello_bot] total = 1.00\n[hello_bot] total = 2.00\n[hello_bot] total = 3.00\n"
    );
    let (code, _, err) = ferroc_in(
        &dir,
        &["types", "export", "--check", "--lib-path", "hello_bot"],
    );
    assert_eq!(code, 0, "{err}");
    // The crate's own unit tests pass.
    let test = Command::new(env!("CARGO"))
        .args(["test", "--quiet", "--manifest-path", "hello_bot/Cargo.toml"])
        .current_dir(&dir)
        .env("CARGO_TARGET_DIR", target())
        .output()
        .unwrap();
    let log = String::from_utf8_lossy(&test.stdout);
    assert!(
        test.status.success(),
        "{log}{}",
        String::from_utf8_lossy(&test.stderr)
    );
    assert!(log.contains("2 passed"), "{log}");
    // Never over an existing folder.
    let (code, _, err) = ferroc_in(&dir, &["new", "library", "hello_bot"]);
    assert_eq!(code, 2);
    assert!(err.contains("exists and is not empty"), "{err}");
    let (code, _, err) = ferroc_in(&dir, &["new", "library", "Bad-Name"]);
    assert_eq!(code, 2);
    assert!(err.contains("cannot name a library"), "{err}");

    // A model of the library's module types, and one of the standard library's.
    let (code, _, err) = ferroc_in(
        &dir,
        &[
            "new",
            "model",
            "mine.xml",
            "--library",
            "hello_bot/hello_bot.lib.xml",
        ],
    );
    assert_eq!(code, 0, "{err}");
    let text = std::fs::read_to_string(dir.join("mine.xml")).unwrap();
    assert!(
        text.contains(r#"<use library="hello_bot" manifest="hello_bot/hello_bot.lib.xml"/>"#),
        "{text}"
    );
    assert!(text.contains(r#"type="hello_bot.Accumulator""#), "{text}");
    let (code, out, err) = ferroc_in(&dir, &["check", "mine.xml", "--format", "short"]);
    assert_eq!(code, 0, "{out}{err}");
    let (code, _, err) = ferroc_in(&dir, &["new", "model", "std.xml"]);
    assert_eq!(code, 0, "{err}");
    let (code, _, err) = ferroc_in(&dir, &["run", "std.xml", "--cycles", "2", "-q"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        !err.contains("building the runner"),
        "the standard library is built in: {err}"
    );
}
