//! `--record` of a model whose part is a ROS 2 node (issue 29, docs/recording-and-
//! utilities.md): every output the node publishes is also recorded on its ROS 2 topic as
//! `cdr` with a `ros2msg` schema. Clients we did not write read the file: Python `mcap`
//! (Foxglove's reader) its channels and schemas, Python `rosbags` every `/cmd_vel` and
//! `/ir_front` message, with types built only from the schema text in the file, to the
//! values the run recorded (its JSON display channels; a lockstep run, so exact). And our
//! `ferroc_std.Player` replays the ROS 2 channels to the same values, bit for bit, as the
//! ports' exact channels (`tests/ros2/replay.xml`).
//!
//! The runs connect to nobody (a node without its router runs all the same); Zenoh's
//! multicast scouting stays off. Without a Python that has `mcap` and `rosbags` the test
//! skips visibly.

mod common;
#[path = "ros2/record_support.rs"]
mod record_support;

use common::tempdir;
use record_support::{channel, read, run};
use serde_json::Value as Json;
use std::path::Path;

const MODEL: &str = "models/ros2_crash_course.xml";
const REPLAY: &str = "tests/ros2/replay.xml";

#[test]
fn ros2_tools_read_a_recorded_node_s_topics_and_our_player_replays_them() {
    let Some(python) = ferroc_testkit::python(&["mcap", "rosbags", "numpy"]) else {
        return;
    };
    let dir = tempdir("ros2_record");
    let record = dir.join("run.mcap");
    let err = run(MODEL, &dir, &["--record", record.to_str().unwrap()]);
    assert!(!err.contains("is not recorded"), "{err}");
    let report = read(&python, &record);

    // The channels: on the ROS 2 topics, cdr with ros2msg schemas, naming their ports.
    for (topic, message, port, field) in [
        (
            "/cmd_vel",
            "geometry_msgs/msg/Twist",
            "fragile_bot/main/control/twist_out/twist",
            None,
        ),
        (
            "/ir_front",
            "std_msgs/msg/Float64",
            "fragile_bot/main/simulation/add_noise_front/output",
            Some("data"),
        ),
    ] {
        let c = channel(&report, topic, "cdr");
        assert_eq!(c["schema_encoding"], "ros2msg", "{c}");
        assert_eq!(c["schema_name"], message, "{c}");
        assert_eq!(c["metadata"]["ferroc.port"], port, "{c}");
        assert_eq!(c["metadata"]["ferroc.form"], "ros2", "{c}");
        assert_eq!(
            c["metadata"].get("ferroc.ros2.field"),
            field.map(Json::from).as_ref()
        );
    }

    // rosbags decodes every message to the value the run recorded.
    let twists = report["ros2"]["/cmd_vel"].as_array().unwrap();
    let shown = report["json"]["fragile_bot/main/control/twist_out/twist"]
        .as_array()
        .unwrap();
    assert!(twists.len() >= 50, "{} /cmd_vel messages", twists.len());
    assert_eq!(
        twists, shown,
        "the Twists rosbags decoded are the recorded values"
    );
    assert!(
        (twists.iter()).any(|t| t["angular"]["z"].as_f64() != Some(0.0)),
        "the robot turned (it looks around first)"
    );
    let ir = report["ros2"]["/ir_front"].as_array().unwrap();
    let noisy = report["json"]["fragile_bot/main/simulation/add_noise_front/output"]
        .as_array()
        .unwrap();
    assert_eq!(ir.len(), noisy.len());
    for (message, value) in ir.iter().zip(noisy) {
        assert_eq!(&message["data"], value, "{message}");
    }

    // `ferroc log cat` prints a ROS 2 channel decoded with its schema's definitions.
    let cat = |topic: &str| -> Vec<Json> {
        let (code, out, err) =
            common::ferroc(&["log", "cat", record.to_str().unwrap(), "--channel", topic]);
        assert_eq!(code, 0, "{err}");
        (out.lines())
            .map(|l| {
                serde_json::from_str(&l.split_once(' ').unwrap().1.replace("\\\"", "\"")).unwrap()
            })
            .collect()
    };
    assert_eq!(
        cat("/cmd_vel"),
        cat("fragile_bot/main/control/twist_out/twist")
    );

    // Our Player: the ROS 2 channels replay as their ports' exact channels do.
    run(REPLAY, &dir, &[]);
    let replay = read(&python, &dir.join("replay.mcap"));
    let values = |topic: &str| replay["json"][topic].as_array().unwrap().clone();
    for (log, recorded) in [("ir_log", noisy), ("twist_log", shown)] {
        let from_cdr = values(&format!("replayer/main/{log}/in/0"));
        let from_exact = values(&format!("replayer/main/{log}/in/1"));
        assert_eq!(from_cdr, from_exact, "{log}: CDR and exact replays agree");
        assert_eq!(&from_exact, recorded, "{log}: the recorded values");
    }
}

/// A bundle's program records the same ports: an output published as a ROS 2 topic is
/// in its `RECORDABLE` table even when it feeds no connection (`/cmd_vel`'s Twist).
#[test]
fn a_bundle_s_program_may_record_every_published_output() {
    let dir = tempdir("ros2_record_bundle");
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join(MODEL);
    common::bundle_ok(&model, &dir.join("bundle"));
    let main = std::fs::read_to_string(dir.join("bundle/parts/fragile_bot/src/main.rs")).unwrap();
    let table = &main[main.find("const RECORDABLE").expect("the table")..];
    let table = &table[..table.find("];").unwrap()];
    assert!(
        table.contains("\"twist\", \"crash_course.Twist\", \"fragile_bot/main\")"),
        "{table}"
    );
    assert_eq!(table.matches("\"twist\"").count(), 1, "once: {table}");
}

/// A recording ferroc did not write: Python `rosbags` writes a rosbag2 bag with MCAP
/// storage (`tests/ros2/write_bag.py`). `ferroc log cat` decodes its /cmd_vel with the
/// bag's own schema, and our Player replays it (a foreign channel: matched by the
/// message's field names) into a `crash_course.Twist` output, to the values sent.
#[test]
fn a_rosbags_bag_is_printed_and_replayed() {
    let Some(python) = ferroc_testkit::python(&["mcap", "rosbags", "numpy"]) else {
        return;
    };
    let dir = tempdir("ros2_record_bag");
    let sent = record_support::script(&python, "write_bag.py", &[dir.join("bag").as_os_str()]);
    let bag = dir.join("bag/bag.mcap");

    let (code, out, err) =
        common::ferroc(&["log", "cat", bag.to_str().unwrap(), "--channel", "/cmd_vel"]);
    assert_eq!(code, 0, "{err}");
    let printed: Vec<Json> = (out.lines())
        .map(|l| serde_json::from_str(&l.split_once(' ').unwrap().1.replace("\\\"", "\"")).unwrap())
        .collect();
    assert_eq!(Json::from(printed), sent);

    run("tests/ros2/replay_bag.xml", &dir, &[]);
    let replay = read(&python, &dir.join("bag_replay.mcap"));
    assert_eq!(replay["json"]["replayer/main/log/in/0"], sent);
}
