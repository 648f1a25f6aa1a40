//! `ferroc run` of the rescue robot (`models/rescue_robot.xml`, crate
//! `components/rescue-components`).
//!
//! The model runs as it is, with its files (the station's victim log and report)
//! moved into a scratch folder. Its one-second logging thread makes `--cycles N` take
//! N seconds, and the robot's exploration depends on the thread timing, so a second
//! test runs a copy in which constants drive the base straight towards the first
//! victim (instead of the planner's command taken apart with `<convert field>`) and
//! the logging thread is left out: there the first detection is predictable.

mod common;

use common::{ferroc, tempdir};
use std::path::{Path, PathBuf};

/// Replaces each `(from, to)` once, insisting that `from` is in the model.
fn edit(text: &mut String, edits: &[(&str, &str)]) {
    for (from, to) in edits {
        assert!(text.contains(from), "`{from}` is not in the model");
        *text = text.replacen(from, to, 1);
    }
}

/// The runnable copy described above, writing its victim report to `report`.
fn runnable_copy(dir: &Path, report: &Path) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut text = std::fs::read_to_string(root.join("models/rescue_robot.xml")).unwrap();
    let manifest = root.join("components/rescue.lib.xml");
    edit(
        &mut text,
        &[
            (
                r#"manifest="../components/rescue.lib.xml""#,
                &format!("manifest=\"{}\"", manifest.display()),
            ),
            (
                r#"<connect from="control/planner/cmd" to="drivers/base/velocity">
      <convert field="linear"/>
    </connect>"#,
                r#"<connect from="control/forward/value" to="drivers/base/velocity"/>"#,
            ),
            (
                r#"<connect from="control/planner/cmd" to="drivers/base/angular_velocity">
      <convert field="angular"/>
    </connect>"#,
                r#"<connect from="control/turn/value" to="drivers/base/angular_velocity"/>"#,
            ),
            (
                r#"<thread name="control" period="50ms" priority="70" cpu="2">"#,
                r#"<thread name="control" period="50ms" priority="70" cpu="2">
      <module name="forward" type="ferroc_std.Constant"><param name="value">0.5</param></module>
      <module name="turn" type="ferroc_std.Constant"><param name="value">0.1</param></module>"#,
            ),
            (
                r#"<connect from="robot/vision/detector/victims" to="station/logging/victim_log/in/0"
           queue="16" on-full="drop-oldest" sharing="on-change" reliability="reliable"/>"#,
                "",
            ),
            (
                r#"<flow name="scan_to_wheels" from="robot/drivers/laser/scan" to="robot/drivers/base/velocity"
        max-latency="300ms"/>"#,
                "",
            ),
            ("/var/lib/rescue/victims.json", report.to_str().unwrap()),
        ],
    );
    let logging = text.find(r#"<thread name="logging""#).unwrap();
    let end = logging + text[logging..].find("</thread>").unwrap() + "</thread>".len();
    text.replace_range(logging..end, "");
    let path = dir.join("rescue_robot.xml");
    std::fs::write(&path, text).unwrap();
    path
}

/// The model with its files in `dir`.
fn model_writing_into(dir: &Path) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut text = std::fs::read_to_string(root.join("models/rescue_robot.xml")).unwrap();
    let manifest = root.join("components/rescue.lib.xml");
    let report = dir.join("victims.json");
    edit(
        &mut text,
        &[
            (
                r#"manifest="../components/rescue.lib.xml""#,
                &format!("manifest=\"{}\"", manifest.display()),
            ),
            ("/var/lib/rescue/victims.json", report.to_str().unwrap()),
        ],
    );
    let path = dir.join("rescue_robot.xml");
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn the_model_runs_robot_and_station() {
    let dir = tempdir("rescue_model");
    let model = model_writing_into(&dir);
    let log_dir = dir.to_str().unwrap();
    let (code, out, err) = ferroc(&[
        "run",
        model.to_str().unwrap(),
        "--for",
        "4s",
        "-q",
        "--log-dir",
        log_dir,
    ]);
    assert_eq!(code, 0, "{out}\n{err}");
    assert!(err.contains("stopped (time is up)"), "{err}");
    // The console's status line once a second, near the start (-4, 0): exploring, or
    // already approaching the first victim if the camera saw it in the first frames
    // (which depends on thread timing).
    let status: Vec<&str> = out
        .lines()
        .filter(|l| l.starts_with("[Rescue station - robot 1] t=") && l.contains("battery"))
        .collect();
    // At least two in 4 s of wall time, also on a loaded machine.
    assert!(status.len() >= 2, "{out}");
    assert_eq!(number(status[0], "t="), 1.0, "{out}");
    assert!(
        status[0].contains("explore") || status[0].contains("approach_victim"),
        "{out}"
    );
    let x = number(status[0], "x=");
    assert!((-4.5..=-2.5).contains(&x), "{out}");
    // The station's heartbeat and victim log.
    assert!(out.contains("station alive, tick: in/0 = 1"), "{out}");
    // The victim log: relative in the model, so under --log-dir.
    let log =
        ferroc_std::recording::Recording::read(&dir.join("logs/rescue/victims.mcap")).unwrap();
    let victims = log.exact_channel("station/logging/victim_log/in/0");
    let victims = victims.unwrap_or_else(|| panic!("{:?}", log.channels));
    assert_eq!(victims.model_type(), "rescue.VictimList");
    // Sampled once a second from the first list on (found early, but when depends on
    // thread timing).
    assert!(victims.count >= 1, "{victims:?}");
}

/// The number after `key` in `line` (`x=` in `x=+1.20 m`).
fn number(line: &str, key: &str) -> f64 {
    let rest = &line[line
        .find(key)
        .unwrap_or_else(|| panic!("no {key} in {line}"))
        + key.len()..];
    let token = rest.split_whitespace().next().unwrap();
    token.trim_end_matches(['°', ',', ')']).parse().unwrap()
}

#[test]
fn the_rescue_robot_runs_and_the_station_reports_the_first_victim() {
    let dir = tempdir("rescue_run");
    let report = dir.join("victims.json");
    let model = runnable_copy(&dir, &report);
    let (code, _, err) = ferroc(&["check", model.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");

    // 80 cycles: 2 s of the 25 ms drivers thread, 4 s of the 50 ms console, 8 s of
    // the 100 ms mission manager.
    let (code, out, err) = ferroc(&["run", model.to_str().unwrap(), "--cycles", "80", "-q"]);
    assert_eq!(code, 0, "{out}\n{err}");
    assert!(err.contains("stopped (cycle limit reached)"), "{err}");
    for thread in ["robot/drivers", "robot/control", "station/gui"] {
        assert!(err.contains(&format!("  {thread}: 80 cycles")), "{err}");
    }
    // Data-triggered: a cycle per scan it was woken for, until the clocked ones end.
    let mapping = err
        .lines()
        .find_map(|l| l.trim().strip_prefix("robot/mapping: "))
        .unwrap_or_else(|| panic!("{err}"));
    let cycles: u64 = mapping.split(' ').next().unwrap().parse().unwrap();
    assert!((40..=80).contains(&cycles), "{err}");

    // The console: a status line per second of its refresh rate (20 Hz: 20 cycles).
    let status: Vec<&str> = out
        .lines()
        .filter(|l| l.contains(" s ") && l.contains("battery"))
        .collect();
    assert_eq!(status.len(), 4, "{out}");
    for (k, line) in status.iter().enumerate() {
        assert!(line.starts_with("[Rescue station - robot 1] t="), "{line}");
        assert_eq!(number(line, "t="), (k + 1) as f64, "{line}");
    }
    // The first victim lies 4.2 m ahead of the start, left of the heading: seen at
    // once as the robot drives towards it, placed within 30 cm of where it lies.
    let found: Vec<&str> = out.lines().filter(|l| l.contains("victim #")).collect();
    assert_eq!(found.len(), 1, "{out}");
    assert!(found[0].contains("victim #1 found"), "{out}");
    let (x, y) = (number(found[0], "x="), number(found[0], "y="));
    assert!(x.hypot(y - 1.2) < 0.3, "{}", found[0]);
    assert!(number(found[0], "(confidence") >= 0.7, "{}", found[0]);
    // Seen, but not yet confirmed (confirming needs 2.4 m): the context switched to
    // approaching it. The constants drove the robot forward at 0.5 m/s from x = -4 m
    // for at most the 2 s the drivers ran.
    let last = status.last().unwrap();
    assert!(last.contains("approach_victim"), "{last}");
    assert!(last.contains("victims 1 (0 confirmed)"), "{last}");
    let x = number(last, "x=");
    assert!((-3.8..=-3.0).contains(&x), "{last}");
    assert!(number(last, "battery") > 25.0, "{last}");

    // The station's victim report.
    let json = std::fs::read_to_string(&report).unwrap();
    assert!(
        json.contains("\"victims\"") && json.contains("\"id\": 1"),
        "{json}"
    );
}
