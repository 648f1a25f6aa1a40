//! `--record` of ROS 2 topics beyond the demo (issue 29, docs/recording-and-utilities.md):
//! values no JSON can hold are recorded on their topics, since the CDR is written
//! straight from the port's value; an input subscribed from a topic is recorded with
//! the values it received; each topic has one ROS 2 channel; and our Player replays a
//! bag of a team's own message type that Python `rosbags` wrote, in a program that is
//! no ROS 2 node. Clients we did not write read the files: Python `mcap` and `rosbags`
//! (`tests/ros2/record_check.py`, its types only from the schema text in the file).
//!
//! The runs connect to nobody but themselves (the two nodes of
//! `tests/ros2/record_topics.xml` share the run's session). Without a Python that has
//! `mcap` and `rosbags` the tests skip visibly.

mod common;
#[path = "ros2/record_support.rs"]
mod record_support;

use common::tempdir;
use ferroc_testkit::free_address;
use record_support::{channel, read, run};
use serde_json::Value as Json;
use std::path::Path;
use std::process::Command;

const MODEL: &str = "tests/ros2/record_topics.xml";

/// The ROS 2 (`cdr`) channels of `report`: (topic, the port in its metadata).
fn ros2_channels(report: &Json) -> Vec<(String, String)> {
    let mut found: Vec<(String, String)> = (report["channels"].as_array().unwrap().iter())
        .filter(|c| c["message_encoding"] == "cdr")
        .map(|c| {
            let port = c["metadata"]["ferroc.port"].as_str().unwrap_or("");
            (c["topic"].as_str().unwrap().to_owned(), port.to_owned())
        })
        .collect();
    found.sort();
    found
}

fn python() -> Option<std::path::PathBuf> {
    ferroc_testkit::python(&["mcap", "rosbags", "numpy"])
}

#[test]
fn non_finite_values_are_recorded_on_their_topics_and_each_topic_once() {
    let Some(python) = python() else {
        return;
    };
    let dir = tempdir("ros2_record_topics");
    let record = dir.join("all.mcap");
    let err = run(MODEL, &dir, &["--record", record.to_str().unwrap()]);
    assert!(!err.contains("is not recorded"), "{err}");
    let report = read(&python, &record);

    // Every value on the topic, as rosbags reads it: none left out.
    for (topic, port, value) in [
        ("/inf", "talker/main/up/output", "inf"),
        ("/neg_inf", "talker/main/down/output", "-inf"),
        ("/nan", "talker/main/both/out", "nan"),
    ] {
        let c = channel(&report, topic, "cdr");
        assert_eq!(c["schema_name"], "std_msgs/msg/Float64", "{c}");
        assert_eq!(c["metadata"]["ferroc.port"], port, "{c}");
        let messages = report["ros2"][topic].as_array().unwrap();
        let shown = report["json"][port].as_array().unwrap();
        assert!(messages.len() >= 50, "{} {topic} messages", messages.len());
        assert_eq!(messages.len(), shown.len(), "{topic}: every recorded value");
        for m in messages {
            assert_eq!(m["data"], value, "{topic}: {m}");
        }
        assert!(shown.iter().all(Json::is_null), "JSON shows them as null");
    }

    // One ROS 2 channel per topic: /tick holds what the talker publishes, though the
    // listener's subscribed input is recorded too (its exact and display channels).
    // A port on no topic (the constant) has none.
    assert_eq!(
        ros2_channels(&report),
        [
            ("/inf".to_owned(), "talker/main/up/output".to_owned()),
            ("/nan".to_owned(), "talker/main/both/out".to_owned()),
            ("/neg_inf".to_owned(), "talker/main/down/output".to_owned()),
            ("/tick".to_owned(), "talker/main/clock/tick".to_owned()),
        ]
    );
    let ticks = report["ros2"]["/tick"].as_array().unwrap();
    let published = report["json"]["talker/main/clock/tick"].as_array().unwrap();
    let data: Vec<&Json> = ticks.iter().map(|t| &t["data"]).collect();
    assert_eq!(data, published.iter().collect::<Vec<_>>());
    channel(&report, "listener/main/echo/in/0", "postcard");
    assert!(report["json"].get("talker/main/huge/value").is_some());
}

#[test]
fn a_subscribed_input_is_recorded_on_its_topic_with_the_values_it_received() {
    let Some(python) = python() else {
        return;
    };
    let dir = tempdir("ros2_record_subscribed");
    let record = dir.join("listener.mcap");
    let args = ["--record", record.to_str().unwrap()];
    run(
        MODEL,
        &dir,
        &[&args[..], &["--record-filter", "listener/*"]].concat(),
    );
    let report = read(&python, &record);

    let c = channel(&report, "/tick", "cdr");
    assert_eq!(c["schema_name"], "std_msgs/msg/UInt64", "{c}");
    assert_eq!(c["schema_encoding"], "ros2msg", "{c}");
    assert_eq!(
        c["metadata"]["ferroc.port"], "listener/main/echo/in/0",
        "{c}"
    );
    assert_eq!(c["metadata"]["ferroc.part"], "listener", "{c}");
    assert_eq!(c["metadata"]["ferroc.form"], "ros2", "{c}");
    let ticks: Vec<Json> = (report["ros2"]["/tick"].as_array().unwrap().iter())
        .map(|t| t["data"].clone())
        .collect();
    let received = report["json"]["listener/main/echo/in/0"]
        .as_array()
        .unwrap();
    assert!(ticks.len() >= 10, "{} ticks received", ticks.len());
    assert_eq!(&ticks, received, "rosbags reads what the input received");
    let counts: Vec<u64> = ticks.iter().map(|t| t.as_u64().unwrap()).collect();
    assert!(
        counts.windows(2).all(|w| w[0] < w[1]),
        "the talker's ticks, in order: {counts:?}"
    );
    // Only the listener's ports: the talker's topics are not in this file.
    assert_eq!(
        ros2_channels(&report),
        [("/tick".to_owned(), "listener/main/echo/in/0".to_owned())]
    );

    // Our Player replays the channel: the values the input received, in a program
    // without a ROS 2 node (`--for 4s` of one message per step replays them all).
    run("tests/ros2/replay_tick.xml", &dir, &[]);
    let replay = read(&python, &dir.join("tick_replay.mcap"));
    assert_eq!(
        replay["json"]["replayer/main/log/in/0"].as_array(),
        Some(&ticks)
    );
}

/// A bag whose message type is a team's own (`team_msgs/msg/Motion`, nesting
/// `team_msgs/msg/Velocity`), written by Python `rosbags`: our Player reads it with the
/// definitions the bag's schema holds and replays it into a `crash_course.Twist` output
/// of a part that is no ROS 2 node, to the values sent.
#[test]
fn a_team_type_bag_rosbags_wrote_replays_in_a_program_without_a_ros2_node() {
    let Some(python) = python() else {
        return;
    };
    let dir = tempdir("ros2_record_team_bag");
    let sent = record_support::script(
        &python,
        "write_team_bag.py",
        &[dir.join("team_bag").as_os_str()],
    );
    assert_eq!(sent.as_array().map(Vec::len), Some(4));

    run("tests/ros2/replay_team_bag.xml", &dir, &[]);
    let replay = read(&python, &dir.join("team_replay.mcap"));
    assert_eq!(replay["json"]["replayer/main/log/in/0"], sent);
}

/// A recording whose ROS 2 channel has an empty schema (Python `mcap` wrote it, the
/// CDR of a team type by Python `rosbags`): the Player reads it with the definitions of
/// the part's ROS 2 node, the model's own package (`<ros2-interfaces>`) among them.
#[test]
fn a_channel_without_definitions_replays_with_the_model_s_team_package() {
    let Some(python) = python() else {
        return;
    };
    let dir = tempdir("ros2_record_schemaless");
    let sent = record_support::script(
        &python,
        "write_schemaless_bag.py",
        &[dir.join("schemaless.mcap").as_os_str()],
    );

    let err = run("tests/ros2/replay_schemaless.xml", &dir, &[]);
    assert!(!err.contains("not replayed"), "{err}");
    let replay = read(&python, &dir.join("schemaless_replay.mcap"));
    assert_eq!(replay["json"]["replayer/main/log/in/0"], sent, "{err}");

    // Compressed chunks (Python mcap's default) are refused as what they are, not as a
    // corrupted file.
    let zstd = dir.join("zstd.mcap");
    record_support::script(
        &python,
        "write_schemaless_bag.py",
        &[zstd.as_os_str(), "zstd".as_ref()],
    );
    let (code, _, err) = common::ferroc(&["log", "info", zstd.to_str().unwrap()]);
    assert_ne!(code, 0);
    assert!(err.contains("compressed with `zstd`"), "{err}");
    assert!(!err.contains("corrupted"), "{err}");
}

/// A bundle's program whose part has links to another part replays a ROS 2 channel
/// (a bag Python `rosbags` wrote): the Player reads it with the bag's schema whatever
/// network the program opens. The other part is not started: the program runs alone.
#[test]
fn a_bundle_part_with_links_replays_a_ros2_channel() {
    let Some(python) = python() else {
        return;
    };
    let dir = tempdir("ros2_record_bundle_linked");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let sent = record_support::script(&python, "write_bag.py", &[dir.join("bag").as_os_str()]);

    let bundle = dir.join("bundle");
    common::bundle_ok(&root.join("tests/ros2/replay_bag_linked.xml"), &bundle);
    let main = std::fs::read_to_string(bundle.join("parts/replayer/src/main.rs")).unwrap();
    assert!(main.contains("Zenoh::with_model"), "a part with links");
    let program = common::build_bundle(&bundle).join("debug/ros2_replay_linked-replayer");
    let (listen, peer) = (free_address(), free_address());
    let run = Command::new(&program)
        .args(["--cycles", "10", "-q", "--listen", &listen])
        .args(["--peer", &format!("sink={peer}")])
        .env("FERROC_LOG_DIR", &dir)
        .current_dir(&dir)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{err}");
    let replay = read(&python, &dir.join("linked_replay.mcap"));
    assert_eq!(replay["json"]["replayer/main/log/in/0"], sent, "{err}");
}
