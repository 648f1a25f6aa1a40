//! `ferroc run` opens a part's ROS 2 node (issue 29, docs/ros2.md): the crash course as
//! the node /fragile_bot, seen by a ROS 2 peer made of clients we did not write
//! (`tests/ros2/run_peer.py`: Python `eclipse-zenoh` and `rosbags`). The peer must see
//! the node's and its topics' liveliness tokens, decode our /cmd_vel samples (rmw_zenoh's
//! key with its own hash, rmw_zenoh's attachment) to the commands the run recorded,
//! and stop the robot by publishing `/enable` `false`.
//!
//! A bundle's program of the same model is the same node: the same peer code checks it.
//!
//! Loopback only: the peer listens on 127.0.0.1, the run connects to it through
//! `ZENOH_SESSION_CONFIG_URI` as a ROS 2 node would to the router; multicast scouting
//! stays off. Without a Python that has `zenoh` and `rosbags` the test skips visibly.

mod common;
/// The demo with /scan, /odom and /goal_pose, beside zenoh-ros2-sdk.
#[path = "ros2_run/demo.rs"]
mod demo;
/// A foreign ROS 2 node of bare Zenoh flooding a topic, for hostile.rs.
#[path = "ros2_run/flooder.rs"]
mod flooder;
/// A foreign node's flood of bad samples, and of requests to a service: reported,
/// throttled; the part runs on.
#[path = "ros2_run/hostile.rs"]
mod hostile;
/// The node and a module's service reached through a Zenoh router, as through rmw_zenohd.
#[path = "ros2_run/router.rs"]
mod router;
/// A ROS 2 service called or offered under another type hash: reported, told.
#[path = "ros2_run/service_hash.rs"]
mod service_hash;

use common::{build_bundle, bundle_ok, ferroc, tempdir, test_log_dir};
use ferroc_testkit::free_port;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

const MODEL: &str = "models/ros2_crash_course.xml";

/// A module's service offered as a ROS 2 service.
const SWITCH: &str = "tests/ros2/switch.xml";
/// A module's client calling a ROS 2 service.
const ASKER: &str = "tests/ros2/asker.xml";

/// A Zenoh configuration connecting to `endpoints`, listening on loopback.
fn zenoh_config(dir: &Path, endpoints: &[&str]) -> PathBuf {
    let file = dir.join("zenoh-connect.json5");
    let text = format!(
        "{{ connect: {{ endpoints: {} }},\n  listen: {{ endpoints: [\"tcp/127.0.0.1:0\"] }} }}\n",
        serde_json::json!(endpoints)
    );
    std::fs::write(&file, text).unwrap();
    file
}

/// A Zenoh configuration listening on loopback's `port`, connecting nowhere.
fn listening_config(dir: &Path, port: u16) -> PathBuf {
    let file = dir.join("zenoh-listen.json5");
    let text = format!(
        "{{ connect: {{ endpoints: [] }},\n  listen: {{ endpoints: [\"tcp/127.0.0.1:{port}\"] }} }}\n"
    );
    std::fs::write(&file, text).unwrap();
    file
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `ferroc run` of the model with this Zenoh configuration.
fn run_command(config: &Path, args: &[&str]) -> Command {
    run_model(MODEL, config, args)
}

/// `ferroc run` of `model` with this Zenoh configuration.
fn run_model(model: &str, config: &Path, args: &[&str]) -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_ferroc"));
    command
        .args(["run", model, "-q"])
        .args(args)
        .env("FERROC_LOG_DIR", test_log_dir())
        .env("ZENOH_SESSION_CONFIG_URI", config)
        .current_dir(env!("CARGO_MANIFEST_DIR"));
    command
}

/// The recorded values of a channel, in order.
fn recorded(file: &Path, channel: &str) -> Vec<f64> {
    let (code, out, err) = ferroc(&["log", "cat", file.to_str().unwrap(), "--channel", channel]);
    assert_eq!(code, 0, "{err}");
    out.lines()
        .filter_map(|l| l.split_once(' ')?.1.parse().ok())
        .collect()
}

/// The runner is built first (outside the timed part) by a run of one cycle with
/// nobody to connect to: a node without its router runs all the same.
fn build_runner(dir: &Path) {
    build_runner_of(MODEL, dir);
}

/// [`build_runner`] for `model`.
fn build_runner_of(model: &str, dir: &Path) {
    let nobody = zenoh_config(dir, &[&format!("tcp/127.0.0.1:{}", free_port())]);
    let first = run_model(model, &nobody, &["--lockstep", "--cycles", "1"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&first.stderr);
    assert!(first.status.success(), "{err}");
}

/// `ferroc run` of the model for at most 30 s, recording into `record`.
fn run_for_30s(config: &Path, record: &Path) -> Command {
    let mut run = run_command(config, &["--for", "30s", "--record"]);
    run.arg(record);
    run
}

/// The zenoh-ros2-sdk peer `tests/ros2/SCRIPT`, connecting to a run listening on
/// `port`, given our shipped interfaces (it computes its own hashes), for 25 s.
fn sdk_peer(python: &Path, port: u16, script: &str) -> Command {
    let mut peer = Command::new(python);
    peer.arg(root().join("tests/ros2").join(script))
        .arg(port.to_string())
        .arg(root().join("ros2/interfaces"))
        .arg("25")
        .env(
            "ZENOH_CONFIG_OVERRIDE",
            "listen/endpoints=[\"tcp/127.0.0.1:0\"]",
        );
    peer
}

/// Runs `model` for 30 s listening on a free port beside the zenoh-ros2-sdk peer
/// `script`: the peer's JSON report and the run's output.
fn sdk_beside(python: &Path, name: &str, model: &str, script: &str) -> (serde_json::Value, String) {
    let dir = tempdir(name);
    build_runner_of(model, &dir);
    let port = free_port();
    let config = listening_config(&dir, port);
    let peer = sdk_peer(python, port, script);
    let run = run_model(model, &config, &["--for", "30s"]);
    run_beside(peer, run)
}

/// What a run beside a peer left: the JSON object the peer printed and its text, the
/// run's standard output and error.
struct Beside {
    report: serde_json::Value,
    text: String,
    out: String,
    err: String,
}

/// Runs `peer` and `run` (the model's node) at once, their output captured, and waits
/// for both: both must end well, the run without a panic, the peer with one JSON object.
fn both(mut peer: Command, mut run: Command) -> Beside {
    let piped = |c: &mut Command| c.stdout(Stdio::piped()).stderr(Stdio::piped()).spawn();
    let (peer, run) = (piped(&mut peer).unwrap(), piped(&mut run).unwrap());
    let peer = peer.wait_with_output().unwrap();
    let run = run.wait_with_output().unwrap();
    let out = String::from_utf8_lossy(&run.stdout).into_owned();
    let err = String::from_utf8_lossy(&run.stderr).into_owned();
    assert!(run.status.success(), "{out}\n{err}");
    assert!(!err.contains("panicked"), "{err}");
    let peer_err = String::from_utf8_lossy(&peer.stderr);
    assert!(peer.status.success(), "{peer_err}");
    let text = String::from_utf8_lossy(&peer.stdout).into_owned();
    let report = serde_json::from_str(text.trim()).expect("one JSON object");
    Beside {
        report,
        text,
        out,
        err,
    }
}

/// Runs `run` (the model's node) beside `peer` ([`both`]), where nothing may be dropped
/// on the way in or out; the JSON object the peer prints, and its text.
fn run_beside(peer: Command, run: Command) -> (serde_json::Value, String) {
    let done = both(peer, run);
    // The run reports such warnings on standard output (`console::report`).
    for dropped in [
        "went wrong",
        "was not published",
        "was dropped",
        "was refused",
        "another type hash",
    ] {
        assert!(!done.err.contains(dropped), "{}", done.err);
        assert!(!done.out.contains(dropped), "{}", done.out);
    }
    (done.report, done.text)
}

#[test]
fn a_ros2_peer_sees_the_node_receives_cmd_vel_and_stops_the_robot_with_enable() {
    let Some(python) = ferroc_testkit::python(&["zenoh", "rosbags"]) else {
        return;
    };
    let dir = tempdir("ros2_run");
    build_runner(&dir);
    let record = dir.join("run.mcap");
    beside_run_peer(&python, &dir, &record, |config| {
        run_for_30s(config, &record)
    });
}

/// A bundle's program of the model is the same node: the ROS 2 peer sees it, receives
/// its /cmd_vel and /ir_front and stops it through /enable, as with `ferroc run`.
#[test]
fn a_bundle_s_program_is_the_node_the_ros2_peer_sees_receives_and_stops() {
    let Some(python) = ferroc_testkit::python(&["zenoh", "rosbags"]) else {
        return;
    };
    let dir = tempdir("ros2_bundle");
    bundle_ok(&root().join(MODEL), &dir.join("bundle"));
    assert_rustfmt_clean(&dir.join("bundle/parts/fragile_bot/src/main.rs"));
    let program = build_bundle(&dir.join("bundle"))
        .join("debug")
        .join("ros2_crash_course-fragile_bot");
    let record = dir.join("bundle.mcap");
    beside_run_peer(&python, &dir, &record, |config| {
        let mut run = Command::new(&program);
        run.args(["-q", "--for", "30s", "--record"])
            .arg(&record)
            .env("FERROC_LOG_DIR", test_log_dir())
            .env("ZENOH_SESSION_CONFIG_URI", config);
        run
    });
    // The program records its published Twist on /cmd_vel as ROS data too
    // (tests/ros2_record.rs reads such a file with mcap and rosbags).
    let cat = |channel: &str| {
        let (code, out, err) =
            ferroc(&["log", "cat", record.to_str().unwrap(), "--channel", channel]);
        assert_eq!(code, 0, "{err}");
        out.lines().count()
    };
    let twists = cat("/cmd_vel");
    assert!(twists > 0 && twists == cat("fragile_bot/main/control/twist_out/twist"));
}

/// The generated programs of a service and a client (not built here): the node with
/// its service or client, their calls registered to cross as JSON, in rustfmt's layout.
#[test]
fn a_bundle_writes_the_node_s_services_and_clients_in_rustfmt_s_layout() {
    let dir = tempdir("ros2_bundle_services");
    for (model, part, end) in [
        (SWITCH, "switch", "services: vec!["),
        (ASKER, "asker", "clients: vec!["),
    ] {
        let out = dir.join(part);
        bundle_ok(&root().join(model), &out);
        let main = out.join(format!("parts/{part}/src/main.rs"));
        let text = std::fs::read_to_string(&main).unwrap();
        assert!(text.contains(end), "{text}");
        assert!(
            text.contains("registry.register_call::<bool, crash_course::Ack>();"),
            "{text}"
        );
        assert!(
            text.contains("network_from(args.zenoh_config.as_deref())"),
            "{text}"
        );
        assert_rustfmt_clean(&main);
    }
}

/// `rustfmt --check` passes on `file` (where rustfmt is installed).
fn assert_rustfmt_clean(file: &Path) {
    if let Ok(out) = Command::new("rustfmt")
        .args(["--edition", "2021", "--check"])
        .arg(file)
        .output()
    {
        let diff = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success(), "{diff}");
    }
}

/// `tests/ros2/run_peer.py` listening on loopback and the node `run(config)` makes
/// connecting to it (as a node connects to rmw_zenohd), recording into `record`: the
/// peer sees the tokens, decodes the samples to the recorded values, and /enable stops
/// the robot.
fn beside_run_peer(python: &Path, dir: &Path, record: &Path, run: impl FnOnce(&Path) -> Command) {
    let port = free_port();
    let config = zenoh_config(dir, &[&format!("tcp/127.0.0.1:{port}")]);
    let mut peer = Command::new(python);
    peer.arg(root().join("tests/ros2/run_peer.py"))
        .args([format!("tcp/127.0.0.1:{port}").as_str(), "25"]);
    let (report, text) = run_beside(peer, run(&config));

    check_tokens(&report);
    let samples = report["samples"].as_array().unwrap();
    check_samples(&report, samples);
    check_values(samples, record);
    check_enable(samples, &text);
    // A single value published into the one field of std_msgs/msg/Float64.
    let ir = report["ir_front"].as_array().unwrap();
    assert!(!ir.is_empty(), "no /ir_front sample: {text}");
    let noisy = recorded(record, "fragile_bot/main/simulation/add_noise_front/output");
    let float = &report["hashes"]["std_msgs/msg/Float64"];
    for s in ir {
        assert_eq!(
            s["key"],
            format!(
                "0/ir_front/std_msgs::msg::dds_::Float64_/{}",
                float.as_str().unwrap()
            )
        );
        let data = s["data"].as_f64().unwrap();
        assert!(
            noisy.contains(&data),
            "/ir_front {data} was never recorded: {s}"
        );
    }
}

/// A module's service offered as a ROS 2 service (`tests/ros2/switch.xml`): the SDK
/// lists it with its type, its client (its own service type hash and key) calls it and
/// gets the module's answers, which switch what the node publishes; a raw request
/// gets rmw_zenoh's reply attachment (the request's sequence number and the client's
/// GID).
#[test]
fn zenoh_ros2_sdk_calls_a_module_s_service_as_a_ros2_service() {
    let Some(python) = ferroc_testkit::python(&["zenoh_ros2_sdk"]) else {
        return;
    };
    let (report, text) = sdk_beside(&python, "ros2_service", SWITCH, "sdk_service_peer.py");

    let listed = serde_json::json!(["/switch_bot/set_enabled", ["std_srvs/srv/SetBool"]]);
    assert!(
        report["services"].as_array().unwrap().contains(&listed),
        "{listed} not in {text}"
    );
    let answer =
        |success: bool, message: &str| serde_json::json!({"success": success, "message": message});
    assert_eq!(
        report["responses"],
        serde_json::json!([answer(true, "disabled"), answer(true, "enabled")]),
        "{text}"
    );
    // /enabled was true, then false after the first call, then true again.
    let enabled: Vec<bool> = (report["enabled"].as_array().unwrap().iter())
        .map(|v| v.as_bool().unwrap())
        .collect();
    let mut changes = enabled.clone();
    changes.dedup();
    assert_eq!(changes.last(), Some(&true), "{text}");
    assert!(changes.ends_with(&[false, true]), "{text}");
    // The raw reply: on the service key, with the request's sequence number (41) and the
    // client's GID (0, 1, …, 15) echoed, as rmw_zenoh's server writes them.
    let raw = &report["raw"];
    assert_eq!(raw["key"], report["key"], "{text}");
    let attachment = raw["attachment"].as_str().unwrap();
    assert_eq!(attachment.len(), 66, "{text}");
    assert_eq!(&attachment[..16], "2900000000000000", "{text}");
    assert_eq!(
        &attachment[32..],
        "10000102030405060708090a0b0c0d0e0f",
        "{text}"
    );
}

/// A module's client calling a ROS 2 service (`tests/ros2/asker.xml`): zenoh-ros2-sdk's
/// server (its own service hash and key, and a strict reading of our request's
/// attachment) gets both kinds of request of `crash_course.EnableAsk` and answers them; the
/// module publishes each answer's message, which the SDK's subscriber receives.
#[test]
fn a_module_s_client_calls_a_zenoh_ros2_sdk_service() {
    let Some(python) = ferroc_testkit::python(&["zenoh_ros2_sdk"]) else {
        return;
    };
    let (report, text) = sdk_beside(&python, "ros2_client", ASKER, "sdk_server_peer.py");

    let requests: Vec<bool> = (report["requests"].as_array().unwrap().iter())
        .map(|v| v.as_bool().unwrap())
        .collect();
    // Calls made before the SDK's server was there time out; the module goes on
    // alternating, so the server sees both values.
    assert!(
        requests.contains(&false) && requests.contains(&true),
        "{text}"
    );
    let answers: Vec<&str> = (report["answers"].as_array().unwrap().iter())
        .map(|v| v.as_str().unwrap())
        .collect();
    for expected in ["python saw False", "python saw True"] {
        assert!(answers.contains(&expected), "{expected} not in {text}");
    }
}

/// `ros2 node list` and `ros2 topic list -t` read these tokens.
fn check_tokens(report: &serde_json::Value) {
    let tokens: Vec<&str> = (report["tokens"].as_array().unwrap().iter())
        .map(|t| t.as_str().unwrap())
        .collect();
    let hash = |t: &str| report["hashes"][t].as_str().unwrap().to_string();
    let twist = format!(
        "/%cmd_vel/geometry_msgs::msg::dds_::Twist_/{}/::,10:,:,:,,",
        hash("geometry_msgs/msg/Twist")
    );
    let float = format!(
        "/%ir_front/std_msgs::msg::dds_::Float64_/{}/2::,10:,:,:,,",
        hash("std_msgs/msg/Float64")
    );
    let enable = format!(
        "/%enable/std_msgs::msg::dds_::Bool_/{}/::,10:,:,:,,",
        hash("std_msgs/msg/Bool")
    );
    let ends = [
        ("/NN/%/%/fragile_bot", String::new()),
        ("/MP/%/%/fragile_bot", twist),
        ("/MP/%/%/fragile_bot", float),
        ("/MS/%/%/fragile_bot", enable),
    ];
    for (entity, topic) in &ends {
        let tail = format!("{entity}{topic}");
        assert!(
            tokens
                .iter()
                .any(|t| t.starts_with("@ros2_lv/0/") && t.ends_with(&tail)),
            "no token ending in {tail} among {tokens:#?}"
        );
    }
}

/// Every sample on rmw_zenoh's key with rosbags' own hash, with the 33-byte attachment,
/// sequence numbers counting up.
fn check_samples(report: &serde_json::Value, samples: &[serde_json::Value]) {
    let hash = report["hashes"]["geometry_msgs/msg/Twist"]
        .as_str()
        .unwrap();
    assert!(samples.len() >= 10, "{samples:?}");
    let key = format!("0/cmd_vel/geometry_msgs::msg::dds_::Twist_/{hash}");
    let mut last = 0;
    for s in samples {
        assert_eq!(s["key"], key.as_str(), "{s}");
        let attachment = s["attachment"].as_str().unwrap();
        assert_eq!(attachment.len(), 66, "33 bytes: {s}");
        let mut sequence = [0u8; 8];
        for (i, b) in sequence.iter_mut().enumerate() {
            *b = u8::from_str_radix(&attachment[2 * i..2 * i + 2], 16).unwrap();
        }
        let sequence = i64::from_le_bytes(sequence);
        assert!(sequence > last, "sequence numbers count up: {s}");
        last = sequence;
        assert_eq!(&attachment[32..34], "10", "the GID's length: {s}");
    }
}

/// The decoded commands are the controller's, as the run recorded them.
fn check_values(samples: &[serde_json::Value], record: &Path) {
    let velocity = recorded(record, "fragile_bot/main/control/controller/velocity");
    let turn = recorded(
        record,
        "fragile_bot/main/control/controller/angular_velocity",
    );
    assert!(!velocity.is_empty() && !turn.is_empty());
    for s in samples {
        let linear = s["linear"].as_array().unwrap();
        let angular = s["angular"].as_array().unwrap();
        let (x, z) = (linear[0].as_f64().unwrap(), angular[2].as_f64().unwrap());
        assert!(
            velocity.contains(&x),
            "linear.x {x} was never recorded: {s}"
        );
        assert!(turn.contains(&z), "angular.z {z} was never recorded: {s}");
        for unused in [&linear[1], &linear[2], &angular[0], &angular[1]] {
            assert_eq!(unused.as_f64(), Some(0.0), "{s}");
        }
    }
}

/// The robot moved, and after the peer's `/enable` `false` it stands still.
fn check_enable(samples: &[serde_json::Value], text: &str) {
    let moving = |s: &serde_json::Value| {
        (s["linear"].as_array().unwrap().iter())
            .chain(s["angular"].as_array().unwrap())
            .any(|v| v.as_f64() != Some(0.0))
    };
    assert!(samples.iter().any(moving), "the robot never moved: {text}");
    let after: Vec<&serde_json::Value> = (samples.iter())
        .filter(|s| s["after_disable"] == true)
        .collect();
    assert!(after.len() >= 10, "too few samples after /enable: {text}");
    assert!(
        after[after.len() - 5..].iter().all(|s| !moving(s)),
        "the robot still moves after /enable false: {text}"
    );
}
