//! `wait=` of a data-triggered container (`park`, `spin`, `adaptive`, `inline`) as
//! `ferroc run` realises it: each mode wakes on data and ends when the run ends (no
//! hang), and in lockstep the four modes print exactly the same. (`inline` runs the
//! container's cycle in the writer's thread, here the periodic `src`.)

mod common;
use common::{bundle_ok, tempdir};
use std::process::Command;

/// A periodic constant feeds a data-triggered container that scales and prints it.
fn model(wait: &str) -> String {
    format!(
        r#"<application name="waits" version="1">
  <use library="ferroc_std"/>
  <part name="p">
    <thread name="src" period="10ms">
      <module name="c" type="ferroc_std.Constant"><param name="value">2</param></module>
    </thread>
    <thread name="ev" trigger="data" wait="{wait}">
      <module name="s" type="ferroc_std.Scale"/>
      <module name="show" type="ferroc_std.Dump">
        <port name="in" dir="in" type="f64" count="1"/>
      </module>
    </thread>
    <connect from="src/c/value" to="ev/s/input"/>
    <connect from="ev/s/output" to="ev/show/in/0"/>
  </part>
</application>
"#
    )
}

/// Runs `ferroc run MODEL ARGS` on the model with `wait`; exit code, stdout, stderr.
fn run(wait: &str, args: &[&str]) -> (i32, String, String) {
    let dir = std::env::temp_dir().join(format!("ferroc_wait_modes_{}_{wait}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("waits.xml");
    std::fs::write(&path, model(wait)).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_ferroc"))
        .arg("run")
        .arg(&path)
        .args(args)
        .output()
        .expect("ferroc runs");
    let _ = std::fs::remove_dir_all(&dir);
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The cycle count the run's summary gives for `container`.
fn cycles(stderr: &str, container: &str) -> u64 {
    let key = format!("{container}: ");
    let line = stderr
        .lines()
        .find_map(|l| l.split_once(&key).map(|(_, rest)| rest.to_string()))
        .unwrap_or_else(|| panic!("no summary for {container}:\n{stderr}"));
    line.split_whitespace()
        .next()
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no count in {line:?}"))
}

#[test]
fn every_wait_mode_wakes_on_data_and_ends_with_the_run() {
    for wait in ["park", "spin", "adaptive", "inline"] {
        let (code, _, err) = run(wait, &["--for", "1s"]);
        assert_eq!(code, 0, "{wait}: {err}");
        // Wall-clock run: only that data woke the container at least once, which holds
        // on any machine (the source's first value is written at once).
        assert!(cycles(&err, "p/ev") >= 1, "{wait}: {err}");
    }
}

#[test]
fn in_lockstep_the_four_modes_print_the_same() {
    let args = ["--lockstep", "--for", "100ms"];
    let (code, park, err) = run("park", &args);
    assert_eq!(code, 0, "{err}");
    assert!(cycles(&err, "p/ev") >= 10, "{err}");
    assert!(!park.is_empty(), "the Dump prints every cycle");
    for wait in ["spin", "adaptive", "inline"] {
        let (code, out, err) = run(wait, &args);
        assert_eq!(code, 0, "{wait}: {err}");
        assert_eq!(out, park, "{wait} printed something else than park");
    }
}

#[test]
fn bundles_wait_as_the_model_says() {
    let dir = tempdir("wait_modes_bundle");
    let path = dir.join("waits.xml");
    std::fs::write(&path, model("spin")).unwrap();
    let out = dir.join("bundle");
    bundle_ok(&path, &out);
    let main = std::fs::read_to_string(out.join("parts/p/src/main.rs")).unwrap();
    assert!(
        main.contains("wait: ferroc_runtime::port::WaitMode::Spin,"),
        "{main}"
    );
    let resolved = std::fs::read_to_string(out.join("model/waits.xml")).unwrap();
    assert!(
        resolved.contains(r#"trigger="data" wait="spin""#),
        "{resolved}"
    );
}
