//! `ferroc run` on the iB2C demo `models/nav_behaviours.xml` and on its twin with
//! deliberate violations, `tests/fixtures/nav_behaviours_violations.xml`.
//!
//! The models run at 25 Hz; tests that need many cycles run a copy whose thread period
//! is 2 ms (the simulation steps a fixed 40 ms per cycle, so the robot's path is the
//! same cycle for cycle).

use std::path::{Path, PathBuf};
use std::process::Command;

fn ferroc(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_ferroc"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("ferroc runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A copy of `model` (relative to the repository) in a fresh folder, with the
/// manifest path made absolute and the given replacements applied.
fn copy(model: &str, name: &str, replace: &[(&str, &str)]) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let mut text = std::fs::read_to_string(root.join(model)).unwrap();
    let manifest = root.join("components/nav_behaviours.lib.xml");
    for prefix in ["../../", "../"] {
        text = text.replace(
            &format!("manifest=\"{prefix}components/nav_behaviours.lib.xml\""),
            &format!("manifest=\"{}\"", manifest.display()),
        );
    }
    for (from, to) in replace {
        assert!(text.contains(from), "`{from}` is not in {model}");
        text = text.replace(from, to);
    }
    let path = dir.join("model.xml");
    std::fs::write(&path, text).unwrap();
    path
}

const FAST: (&str, &str) = (r#"period="40ms""#, r#"period="2ms""#);

/// The activities of a status line: (goal, wall, avoid).
fn activities(line: &str) -> Option<(f64, f64, f64)> {
    let after = |key: &str| -> Option<f64> {
        let rest = &line[line.find(key)? + key.len()..];
        rest.split_whitespace().next()?.parse().ok()
    };
    Some((after("goal ")?, after("wall ")?, after("avoid ")?))
}

#[test]
fn the_demo_checks_clean() {
    let (code, out, err) = ferroc(&["check", "models/nav_behaviours.xml", "--format", "short"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.trim().is_empty(), "no findings expected:\n{out}");
}

#[test]
fn the_demo_runs_and_prints_activities_and_the_fused_command() {
    let (code, out, err) = ferroc(&["run", "models/nav_behaviours.xml", "--cycles", "30"]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("robot/control: 30 cycles, "), "{err}");
    // One status line per simulated second; at first only goal following acts.
    let lines: Vec<&str> = out.lines().filter(|l| l.starts_with("[nav] t=")).collect();
    assert_eq!(lines.len(), 1, "{out}");
    assert!(
        lines[0].starts_with("[nav] t=  1.0 s x=-2.65 y=-2.20"),
        "{out}"
    );
    assert_eq!(activities(lines[0]), Some((1.0, 0.0, 0.0)), "{out}");
    assert!(lines[0].contains("fused linear +0.50 m/s"), "{out}");
    assert!(
        !out.contains("violation") && !err.contains("violation"),
        "{out}{err}"
    );
}

#[test]
fn the_robot_follows_the_pillar_and_reaches_the_goal() {
    // In lockstep: the simulation steps by its container's period, so 800 cycles of
    // 40 ms are 32 s of model time however fast the machine runs them.
    let model = copy("models/nav_behaviours.xml", "nav_lockstep", &[]);
    let (code, out, err) = ferroc(&[
        "run",
        model.to_str().unwrap(),
        "--lockstep",
        "--cycles",
        "800",
    ]);
    assert_eq!(code, 0, "{err}");
    let all: Vec<(f64, f64, f64)> = out.lines().filter_map(activities).collect();
    assert_eq!(all.len(), 32, "{out}");
    // Wall following takes over from goal following at the pillar (mutual inhibition:
    // the two activities add up to 1 while neither is inhibited by an emergency)...
    let (goal, wall, _) = all
        .iter()
        .copied()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap();
    assert!(wall > 0.5 && goal < 0.5, "{out}");
    assert!((goal + wall - 1.0).abs() < 0.011, "{out}");
    // ... and hands back: the robot reaches the goal without touching anything.
    assert!(out.contains("goal reached at x=+2.8"), "{out}");
    assert_eq!(all.last().map(|a| a.0), Some(1.0), "{out}");
    assert!(!out.contains("[sim] bump"), "{out}");
    assert!(
        !out.contains("violation") && !err.contains("violation"),
        "{out}{err}"
    );
}

const TWIN: &str = "tests/fixtures/nav_behaviours_violations.xml";

#[test]
fn the_twin_has_the_static_findings() {
    let (code, out, err) = ferroc(&["check", TWIN, "--format", "short"]);
    assert_eq!(code, 0, "warnings only: {out}{err}");
    assert!(
        out.contains(
            ":44:21: warning[B103]: behaviour `robot/control/faulty` can never become active"
        ),
        "{out}"
    );
    assert!(
        out.contains(":49:40: warning[B104]: behaviour `robot/control/go_to_goal` is `enabled`"),
        "{out}"
    );
    assert_eq!(
        out.lines().filter(|l| l.contains("warning[")).count(),
        2,
        "{out}"
    );
}

#[test]
fn the_twin_reports_the_violation_once_and_clamps_it() {
    let (code, out, err) = ferroc(&["run", TWIN, "--cycles", "30"]);
    assert_eq!(code, 0, "{err}");
    let reports: Vec<&str> = out
        .lines()
        .filter(|l| l.contains("iB2C principle violation"))
        .collect();
    assert_eq!(
        reports,
        [
            "warning: iB2C principle violation in `robot/control/faulty` (activity limitation): \
         activity 0.7 exceeds activation 0; corrected (policy clamp: further violations of \
         this rule are counted, not reported)"
        ],
        "{out}"
    );
    assert!(
        err.contains("iB2C principle violations:\n  robot/control/faulty: 30 × activity limitation (policy clamp)"),
        "{err}"
    );
}

#[test]
fn under_warn_the_twin_reports_every_250_cycles() {
    let model = copy(
        TWIN,
        "twin_warn",
        &[
            FAST,
            (r#"ib2c-violations="clamp""#, r#"ib2c-violations="warn""#),
        ],
    );
    let (code, out, err) = ferroc(&["run", model.to_str().unwrap(), "--cycles", "300"]);
    assert_eq!(code, 0, "{err}");
    let reports: Vec<&str> = out
        .lines()
        .filter(|l| l.contains("iB2C principle violation in `robot/control/faulty`"))
        .collect();
    assert_eq!(reports.len(), 2, "{out}");
    assert!(reports[0].ends_with("passed on unchanged"), "{out}");
    assert!(
        reports[1].ends_with("[249 more since the last report]"),
        "{out}"
    );
    assert!(
        err.contains("robot/control/faulty: 300 × activity limitation (policy warn)"),
        "{err}"
    );
}

#[test]
fn a_module_policy_stop_stops_only_that_module() {
    let model = copy(
        TWIN,
        "twin_stop",
        &[(
            r#"<module name="faulty" type="nav_behaviours.FaultInjector">"#,
            r#"<module name="faulty" type="nav_behaviours.FaultInjector" ib2c-violations="stop">"#,
        )],
    );
    let (code, out, err) = ferroc(&["run", model.to_str().unwrap(), "--cycles", "30"]);
    assert_eq!(code, 1, "{out}{err}");
    let all = format!("{out}{err}");
    assert!(
        all.contains("error: `robot/control/faulty:update` was stopped: iB2C principle violation in `robot/control/faulty` (activity limitation): activity 0.7 exceeds activation 0; the module is stopped (policy stop)"),
        "{all}"
    );
    // The rest ran on: the monitor printed its status line.
    assert!(out.contains("[nav] t=  1.0 s"), "{out}");
    assert!(
        err.contains("robot/control/faulty: 1 × activity limitation (policy stop)"),
        "{err}"
    );
}

#[test]
fn the_standard_types_agree_with_their_manifest_and_fuse() {
    // Every implemented ferroc_std type in one model: `ferroc run` refuses a type whose
    // Rust interface differs from the manifest, so running at all is the agreement.
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("std_types");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let model = dir.join("m.xml");
    std::fs::write(
        &model,
        r#"<application name="std" version="1">
  <use library="ferroc_std"/>
  <part name="p">
    <thread name="t" period="2ms">
      <module name="u0" type="ferroc_std.Constant"><param name="value">2</param></module>
      <module name="u1" type="ferroc_std.Constant"><param name="value">4</param></module>
      <module name="a0" type="ferroc_std.ConstantActivity"><param name="value">0.75</param></module>
      <module name="a1" type="ferroc_std.NumberToActivity"><param name="max">16</param></module>
      <module name="r" type="ferroc_std.ConstantActivity"><param name="value">0.5</param></module>
      <module name="fusion" type="ferroc_std.Fusion">
        <param name="stimulation_mode">enabled</param>
        <param name="method">weighted_sum</param>
      </module>
      <module name="double" type="ferroc_std.Scale"><param name="factor">2</param></module>
      <connect from="a0/activity" to="fusion/in/0/activity"/>
      <connect from="r/activity" to="fusion/in/0/target_rating"/>
      <connect from="u0/value" to="fusion/in/0/value"/>
      <connect from="u1/value" to="a1/value"/>
      <connect from="a1/activity" to="fusion/in/1/activity"/>
      <connect from="r/activity" to="fusion/in/1/target_rating"/>
      <connect from="u1/value" to="fusion/in/1/value"/>
      <connect from="fusion/value" to="double/input"/>
    </thread>
  </part>
</application>
"#,
    )
    .unwrap();
    let (code, out, err) = ferroc(&["run", model.to_str().unwrap(), "--cycles", "5"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(err.contains("p/t: 5 cycles"), "{err}");
    assert!(!err.contains("error"), "{err}");
}

#[test]
fn a_behaviour_whose_manifest_disagrees_is_refused() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("behaviour_mismatch");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let manifest = std::fs::read_to_string(root.join("components/nav_behaviours.lib.xml"))
        .unwrap()
        .replace(
            r#"<derived-activity name="arrived"/>"#,
            r#"<derived-activity name="arrived"/><derived-activity name="lost"/>"#,
        )
        .replace(
            r#"<channel-in name="angular" type="f64" unit="rad/s"/>"#,
            r#"<channel-in name="angular" type="f64" unit="deg/s"/>"#,
        );
    let manifest_path = dir.join("nav_behaviours.lib.xml");
    std::fs::write(&manifest_path, manifest).unwrap();
    let text = std::fs::read_to_string(root.join("models/nav_behaviours.xml"))
        .unwrap()
        .replace(
            r#"manifest="../components/nav_behaviours.lib.xml""#,
            &format!(r#"manifest="{}""#, manifest_path.display()),
        );
    let model = dir.join("m.xml");
    std::fs::write(&model, text).unwrap();
    let (code, out, err) = ferroc(&["run", model.to_str().unwrap(), "--cycles", "1"]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(
        err.contains(
            r#"the manifest declares <meta-out name="activity/lost">, the code has no such port"#
        ),
        "{err}"
    );
    assert!(
        err.contains(r#"channel port `in/0/angular`: the manifest's <channel-in name="angular"> says unit `deg/s`, the code `rad/s`"#),
        "{err}"
    );
}
