//! `ferroc run` and `ferroc bundle` give each thread container the priority and CPU
//! the model declares, and run on (with a warning) where the OS refuses.

mod common;
use common::{bundle_ok, ferroc, tempdir};

/// One periodic container pinned to `cpu` with `priority`.
fn model(cpu: &str, priority: &str) -> String {
    format!(
        r#"<application name="placed" version="1">
  <use library="ferroc_std"/>
  <part name="p">
    <thread name="t" period="1ms" cpu="{cpu}" priority="{priority}">
      <module name="c" type="ferroc_std.Constant"/>
      <module name="s" type="ferroc_std.Scale"/>
    </thread>
    <connect from="t/c/value" to="t/s/input"/>
  </part>
</application>
"#
    )
}

#[test]
fn a_cpu_the_machine_lacks_is_a_warning_and_the_model_still_runs() {
    let dir = tempdir("run_options_cpu");
    let path = dir.join("placed.xml");
    std::fs::write(&path, model("1000", "1")).unwrap();
    let (code, _, stderr) = ferroc(&["run", path.to_str().unwrap(), "--cycles", "3", "-q"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stderr.contains("pinning to CPU 1000 refused"),
        "the model's cpu= reaches the thread: {stderr}"
    );
    assert!(stderr.contains("p/t: 3 cycles"), "{stderr}");
}

#[test]
fn an_existing_cpu_gives_no_warning() {
    let dir = tempdir("run_options_cpu0");
    let path = dir.join("placed.xml");
    std::fs::write(&path, model("0", "1")).unwrap();
    let (code, _, stderr) = ferroc(&["run", path.to_str().unwrap(), "--cycles", "3", "-q"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(!stderr.contains("pinning"), "{stderr}");
}

#[test]
fn bundles_write_the_same_placement() {
    let dir = tempdir("run_options_bundle");
    let path = dir.join("placed.xml");
    // Priorities above the OS range are clamped to it (SCHED_FIFO: 1-99).
    std::fs::write(&path, model("1", "250")).unwrap();
    let out = dir.join("bundle");
    bundle_ok(&path, &out);
    let main = std::fs::read_to_string(out.join("parts/p/src/main.rs")).unwrap();
    assert!(main.contains("priority: Some(99),"), "{main}");
    assert!(main.contains("cpu: Some(1),"), "{main}");
    // The resolved model keeps them too, so it reproduces the same application.
    let resolved = std::fs::read_to_string(out.join("model/placed.xml")).unwrap();
    assert!(
        resolved.contains(r#"period="1ms" priority="250" cpu="1""#),
        "{resolved}"
    );
}

/// `--lockstep --for` counts model time: 1 s of a 40 ms container is the instants 0,
/// 40, …, 1000 ms, however fast the machine, and the run prints the same every time.
#[test]
fn lockstep_runs_for_model_time_and_repeats_exactly() {
    let model = "models/nav_behaviours.xml";
    let args = ["run", model, "--lockstep", "--for", "1s", "-q"];
    let (code, out, err) = ferroc(&args);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("stopped (model time is up)"), "{err}");
    assert!(err.contains("robot/control: 26 cycles"), "{err}");
    assert!(out.contains("[nav] t=  1.0 s"), "{out}");
    let (_, again, _) = ferroc(&args);
    assert_eq!(out, again);
}
