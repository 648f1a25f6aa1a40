//! Recording and replay through the CLI: the demo models (a run that logs, a run that
//! replays the log into the controller), `ferroc run --record`, `ferroc log`, and the
//! files read by an MCAP reader we did not write (the Python `mcap` package; CI
//! installs it, see scripts/test and FERROC_PYTHON).

mod common;
use common::{ferroc, python, tempdir};
use ferroc_std::recording::Recording;
use std::path::Path;
use std::process::Command;

const EPOCH: u64 = 946_684_800_000_000_000;

fn exact(rec: &Recording, topic: &str) -> Vec<(u64, Vec<u8>)> {
    let id = rec
        .exact_channel(topic)
        .unwrap_or_else(|| panic!("no {topic} in {:?}", rec.channels))
        .id;
    rec.messages
        .iter()
        .filter(|m| m.channel == id)
        .map(|m| (m.log_time, m.data.clone()))
        .collect()
}

fn run(model: &str, dir: &Path, extra: &[&str]) -> String {
    run_for(model, "2s", dir, extra)
}

fn run_for(model: &str, time: &str, dir: &Path, extra: &[&str]) -> String {
    let mut args = vec!["run", model, "--lockstep", "--for", time, "-q", "--log-dir"];
    args.push(dir.to_str().unwrap());
    args.extend_from_slice(extra);
    let (code, out, err) = ferroc(&args);
    assert_eq!(code, 0, "{out}\n{err}");
    err
}

/// The README's pair as printed (20 s each): the replay feeds the controller everything
/// it read (pose and both distances), so every command of the whole run is the same, bit
/// for bit. Before the pose was recorded and replayed, 173 of 501 velocities differed
/// (the robot turned in place for the first 2 s, which hid it).
#[test]
fn the_logged_demo_replays_into_the_controller_with_identical_commands() {
    let dir = tempdir("recording_demo");
    run_for("models/crash_course_logged.xml", "20s", &dir, &[]);
    run_for("models/crash_course_replay.xml", "20s", &dir, &[]);
    let live = Recording::read(&dir.join("logs/crash_course.mcap")).unwrap();
    let replay = Recording::read(&dir.join("logs/crash_course_replay.mcap")).unwrap();
    // 20 s of a 40 ms container: the instants 0, 40 ms, …, 20 s.
    let front = exact(&live, "fragile_bot/main/sensor_log/in/0");
    assert_eq!(front.len(), 501);
    assert_eq!(front.last().unwrap().0, EPOCH + 20_000_000_000);
    assert_eq!(exact(&live, "fragile_bot/main/pose_log/in/0").len(), 501);
    for log in ["velocity_log", "turn_log"] {
        let topic = format!("fragile_bot/main/{log}/in/0");
        let commands = exact(&live, &topic);
        assert_eq!(commands.len(), 501);
        assert_eq!(exact(&replay, &topic), commands, "{topic}");
    }
    // The robot drove (not only turned in place): the comparison covers driving.
    let velocity = exact(&live, "fragile_bot/main/velocity_log/in/0");
    let driving = velocity
        .iter()
        .filter(|(_, bytes)| bytes.iter().any(|b| *b != 0))
        .count();
    assert!(driving > 50, "{driving} of 501 commands drive");
}

#[test]
fn record_writes_every_connection_and_log_shows_it() {
    let dir = tempdir("recording_record");
    let file = dir.join("run.mcap");
    let err = run(
        "models/crash_course.xml",
        &dir,
        &["--record", file.to_str().unwrap()],
    );
    // Pose2D is registered with its serde form: recorded like the rest, nothing left out.
    assert!(!err.contains("--record leaves out"), "{err}");
    let (code, out, err) = ferroc(&["log", "info", file.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains(": finished"), "{out}");
    // Lockstep: model time from the run's start, not seconds since 1970.
    assert!(
        out.contains("time: model time (lockstep) from the run's start"),
        "{out}"
    );
    assert!(
        out.contains("messages from 0.000000000 to 2.000000000 s (2.000000000 s)"),
        "{out}"
    );
    let line = out
        .lines()
        .find(|l| l.contains("control/controller/velocity  [postcard]"))
        .unwrap_or_else(|| panic!("{out}"));
    // The unit of the recorded port (the manifest's `m/s`), per channel.
    assert!(
        line.contains("type f64  unit m/s  part fragile_bot  51 message(s)"),
        "{line}"
    );
    let (_, absolute, _) = ferroc(&["log", "info", file.to_str().unwrap(), "--absolute-time"]);
    assert!(
        absolute.contains("messages from 946684800.000000000 to 946684802.000000000 s"),
        "{absolute}"
    );
    let pose = out
        .lines()
        .find(|l| l.contains("simulation/main_simulation/pose  [postcard]"))
        .unwrap_or_else(|| panic!("{out}"));
    assert!(pose.contains("type crash_course.Pose2D"), "{pose}");
    // A filter records only what matches.
    let some = dir.join("some.mcap");
    run(
        "models/crash_course.xml",
        &dir,
        &[
            "--record",
            some.to_str().unwrap(),
            "--record-filter",
            "*/velocity",
        ],
    );
    let rec = Recording::read(&some).unwrap();
    let topics: std::collections::BTreeSet<&str> =
        rec.channels.values().map(|c| c.topic.as_str()).collect();
    assert_eq!(
        topics.into_iter().collect::<Vec<_>>(),
        ["fragile_bot/main/control/controller/velocity"]
    );
    let (code, out, _) = ferroc(&[
        "log",
        "cat",
        some.to_str().unwrap(),
        "--channel",
        "fragile_bot/main/control/controller/velocity",
    ]);
    assert_eq!(code, 0);
    assert_eq!(out.lines().count(), 51);
    // Model time from the start, 40 ms apart; the recorded time on request.
    let times: Vec<&str> = out.lines().filter_map(|l| l.split(' ').next()).collect();
    assert_eq!(
        (times[0], times[1], times[50]),
        ("0.000000000", "0.040000000", "2.000000000"),
        "{out}"
    );
    let (code, out, _) = ferroc(&[
        "log",
        "cat",
        some.to_str().unwrap(),
        "--channel",
        "fragile_bot/main/control/controller/velocity",
        "--absolute-time",
    ]);
    assert_eq!(code, 0);
    assert!(out.starts_with("946684800.000000000 "), "{out}");
    assert!(out.contains("\n946684800.040000000 "), "{out}");
    // Not a recording, an unknown channel: exit 2 with a message.
    let (code, _, err) = ferroc(&["log", "info", "Cargo.toml"]);
    assert_eq!(code, 2);
    assert!(err.contains("is not an MCAP file"), "{err}");
    let (code, _, err) = ferroc(&["log", "cat", some.to_str().unwrap(), "--channel", "x"]);
    assert_eq!(code, 2);
    assert!(
        err.contains("no JSON or ROS 2 channel `x`") && err.contains("help: its topics are"),
        "{err}"
    );
}

#[test]
fn an_unusable_log_path_is_refused_before_the_run_with_a_message() {
    let dir = tempdir("recording_unwritable");
    // A file where the log folder should be: the logger cannot create `logs/`.
    std::fs::write(dir.join("logs"), "not a folder").unwrap();
    let (code, out, err) = ferroc(&[
        "run",
        "models/crash_course_logged.xml",
        "--lockstep",
        "--for",
        "1s",
        "-q",
        "--log-dir",
        dir.to_str().unwrap(),
    ]);
    // Refused when the logger is created: the path is checked before the run.
    assert_eq!(code, 1, "{out}");
    assert!(err.contains("is not a folder"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn the_python_mcap_reader_reads_what_the_model_implies() {
    let Some(python) = python() else { return };
    let dir = tempdir("recording_python");
    run("models/crash_course_logged.xml", &dir, &[]);
    let file = dir.join("logs/crash_course.mcap");
    let script = r#"
import json, sys
import jsonschema
from mcap.reader import make_reader
with open(sys.argv[1], "rb") as f:
    reader = make_reader(f)
    summary = reader.get_summary()
    channels = {c.id: c for c in summary.channels.values()}
    out = {"channels": [], "times": {}, "json_ok": 0}
    for c in sorted(channels.values(), key=lambda c: c.id):
        s = summary.schemas[c.schema_id]
        out["channels"].append([c.topic, c.message_encoding, s.name, s.encoding,
                                summary.statistics.channel_message_counts[c.id],
                                c.metadata["ferroc.part"], c.metadata["ferroc.unit"],
                                c.metadata["ferroc.type"]])
    out["run"] = [m.metadata for m in reader.iter_metadata() if m.name == "ferroc.run"]
    for schema, channel, message in reader.iter_messages():
        out["times"].setdefault(channel.topic, []).append(message.log_time)
        if channel.message_encoding == "json":
            jsonschema.validate(json.loads(message.data), json.loads(schema.data))
            out["json_ok"] += 1
print(json.dumps(out))
"#;
    let output = Command::new(&python)
        .args(["-c", script, file.to_str().unwrap()])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    let v: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let channel = |topic: &str, enc: &str, ty: &str, unit: &str| {
        serde_json::json!([
            format!("fragile_bot/main/{topic}"),
            enc,
            ty,
            if enc == "json" {
                "jsonschema"
            } else {
                "ferroc-type"
            },
            51,
            "fragile_bot",
            unit,
            ty
        ])
    };
    // Each channel's unit: what the logger's input receives, the unit of the output
    // feeding it (noise module `m`, controller `m/s` and `rad/s`); a pose has none.
    let mut expected = Vec::new();
    for (topic, ty, unit) in [
        ("sensor_log/in/0", "f64", "m"),
        ("sensor_log/in/1", "f64", "m"),
        ("velocity_log/in/0", "f64", "m/s"),
        ("turn_log/in/0", "f64", "rad/s"),
        ("pose_log/in/0", "crash_course.Pose2D", ""),
    ] {
        expected.push(channel(topic, "postcard", ty, unit));
        expected.push(channel(topic, "json", ty, unit));
    }
    let mut got = v["channels"].as_array().unwrap().clone();
    got.sort_by_key(|c| c.to_string());
    expected.sort_by_key(|c| c.to_string());
    assert_eq!(got, expected);
    // The run's clock and start: model time, counted from the lockstep epoch.
    assert_eq!(
        v["run"],
        serde_json::json!([{"clock": "lockstep", "start": EPOCH.to_string(), "seed": "1"}])
    );
    // Log times: every 40 ms of model time from the lockstep epoch, for every topic.
    let want: Vec<u64> = (0..51).map(|k| EPOCH + k * 40_000_000).collect();
    for (topic, times) in v["times"].as_object().unwrap() {
        let times: Vec<u64> = times
            .as_array()
            .unwrap()
            .iter()
            .map(|t| t.as_u64().unwrap())
            .collect();
        // Two channels per topic: each instant twice.
        let once: Vec<u64> = times.iter().step_by(2).copied().collect();
        assert_eq!(once, want, "{topic}");
    }
    assert_eq!(
        v["json_ok"],
        5 * 51,
        "every JSON message validates against its schema"
    );
}

#[test]
fn a_log_folder_that_cannot_be_created_is_reported_and_the_run_goes_on() {
    // /proc takes no new folders, not even from root: the loggers fail when they open
    // the file, after the checks at creation passed.
    let (code, out, err) = ferroc(&[
        "run",
        "models/crash_course_logged.xml",
        "--lockstep",
        "--for",
        "1s",
        "-q",
        "--log-dir",
        "/proc/self/ferroc-test",
    ]);
    // The run goes on, but its recordings are lost: the exit code says so (it was 0).
    assert_eq!(code, 3, "{out}\n{err}");
    assert!(err.contains("data lost (exit code 3):"), "{err}");
    assert!(
        err.contains("warning: ferroc_std.Logger: cannot write the recording `/proc/self/ferroc-test/logs/crash_course.mcap`"),
        "{err}"
    );
    assert!(err.contains("it records nothing more"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    // The application ran its whole second: 26 cycles of 40 ms.
    assert!(err.contains("fragile_bot/main: 26 cycles"), "{err}");
}

/// `ferroc_std.Player timestamps=now`: a clock recorded every 40 ms, replayed one
/// message per 100 ms step, carries the replay's time (each stamp moved by how much
/// later it is replayed than recorded); `timestamps=recorded` keeps the recorded ones.
#[test]
fn replayed_timestamps_can_be_shifted_to_now() {
    let dir = tempdir("recording_shift");
    run("tests/fixtures/clock_logged.xml", &dir, &[]);
    run("tests/fixtures/clock_replay.xml", &dir, &[]);
    let rec = Recording::read(&dir.join("clock_replay.mcap")).unwrap();
    let json = |topic: &str| -> Vec<(u64, String)> {
        let id = (rec.channels.values())
            .find(|c| c.topic == topic && c.message_encoding == "json")
            .unwrap_or_else(|| panic!("no {topic}"))
            .id;
        (rec.messages.iter())
            .filter(|m| m.channel == id)
            .map(|m| (m.log_time, String::from_utf8(m.data.clone()).unwrap()))
            .collect()
    };
    // The JSON form of a `timestamp`: nanoseconds since the Unix epoch.
    let stamp = |nanos: u64| format!("{{\"nanos\":{nanos}}}");
    let shifted = json("clocks/main/log/in/0");
    let kept = json("clocks/main/log/in/1");
    // 2 s of 100 ms steps: 21 instants, each replaying the next recorded message.
    assert_eq!(shifted.len(), 21);
    assert_eq!(kept.len(), 21);
    for (k, ((at, now), (_, recorded))) in shifted.iter().zip(&kept).enumerate() {
        let k = k as u64;
        assert_eq!(*at, EPOCH + k * 100_000_000);
        assert_eq!(*now, stamp(*at), "step {k}: shifted to the replay's time");
        assert_eq!(
            *recorded,
            stamp(EPOCH + k * 40_000_000),
            "step {k}: as recorded"
        );
    }
}

/// Issue 27 item 17: `log info` printed topic names as they are, ESC and BEL
/// included (this test failed so before the fix); they are escaped as everywhere.
#[test]
fn log_info_escapes_control_characters_of_topics() {
    use ferroc_std::recording::{ChannelInfo, LogFile};
    let dir = tempdir("recording_hostile_topic");
    let file = dir.join("hostile.mcap");
    {
        let log = LogFile::open_shared(&file, 1).unwrap();
        let mut log = log.lock().unwrap();
        let info = ChannelInfo {
            topic: "robot/\u{1b}[2Jgone\u{7}\nfake line".into(),
            part: "p\u{1b}]0;title\u{7}".into(),
            model_type: "f64".into(),
            ..ChannelInfo::default()
        };
        let ch = log.channel(&info).unwrap();
        log.write(ch, 1, &1.5f64.to_le_bytes(), None).unwrap();
        log.finish().unwrap();
    }
    let (code, out, err) = ferroc(&["log", "info", file.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(!out.contains('\u{1b}') && !out.contains('\u{7}'), "{out:?}");
    assert!(
        out.contains("robot/\\u{1b}[2Jgone\\u{7}\\u{a}fake line"),
        "{out}"
    );
    assert!(out.contains("part p\\u{1b}]0;title\\u{7}"), "{out}");
    // State, count, what the times are, their span, the one channel.
    assert_eq!(out.lines().count(), 5, "{out}");
}

/// A logger whose input receives nothing still leaves its file: created at the first
/// step, finished on stop, an empty recording that `ferroc log info` (and any MCAP
/// reader) reads. Before, the file was created at the first value: no file at all.
#[test]
fn a_logger_that_receives_nothing_leaves_an_empty_valid_recording() {
    let dir = tempdir("recording_empty");
    let model = dir.join("quiet.xml");
    std::fs::write(
        &model,
        r#"<application name="quiet" version="1">
  <use library="ferroc_std"/>
  <part name="p" host="localhost">
    <thread name="main" period="10ms">
      <module name="log" type="ferroc_std.Logger">
        <port name="in" dir="in" type="f64" unit="m" count="1"/>
        <param name="file">quiet.mcap</param>
      </module>
    </thread>
  </part>
</application>
"#,
    )
    .unwrap();
    let (code, out, err) = ferroc(&[
        "run",
        model.to_str().unwrap(),
        "--lockstep",
        "--cycles",
        "3",
        "-q",
        "--log-dir",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{out}\n{err}");
    let file = dir.join("quiet.mcap");
    assert!(file.is_file(), "no recording: {err}");
    let rec = Recording::read(&file).unwrap();
    assert!(rec.finished, "the empty recording is finished on stop");
    assert!(rec.messages.is_empty());
    let (code, out, err) = ferroc(&["log", "info", file.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains(": finished"), "{out}");
}
