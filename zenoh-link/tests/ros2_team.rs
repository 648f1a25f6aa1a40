//! A team's own message package (`<ros2-interfaces>`, docs/ros2.md) on rmw_zenoh's
//! wire, against clients we did not write (`tests/python/ros2_team.py`): Python
//! `rosbags`, with the same `.msg` files registered, computes the same RIHS01 hash as
//! the one in our key and deserialises our sample (a nested team type in a bounded
//! array, a shipped nested type, a constant and a default) to the values we sent; its
//! sample, on the key it builds from its own hash, reaches our subscription.
//!
//! The package is the fixture of check R109 (`team/robot_msgs`). Loopback only,
//! multicast scouting off; without a Python that has `zenoh` and `rosbags` the test
//! skips visibly (ferroc-testkit).

mod support;

use ferroc_ros2::def::TypeName;
use ferroc_ros2::rmw_zenoh::Qos;
use ferroc_ros2::{cdr, json, Registry};
use ferroc_runtime::link::ros2::{Ros2Interface, Ros2Node as NodeDescription};
use ferroc_runtime::link::transport::Addresses;
use ferroc_zenoh::ros2::{interfaces, NodeSpec, Ros2Node, TopicSpec};
use serde_json::json;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::{Arc, Mutex};
use zenoh::Wait;

fn package() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../compiler/checks/src/ros2/r109_invalid_ros2_interfaces/team/robot_msgs")
}

/// The package's definitions as a node carries them (what the plan gives the runtime).
fn carried() -> NodeDescription {
    let mut interfaces = Vec::new();
    for kind in ["msg", "srv"] {
        let mut files: Vec<_> = std::fs::read_dir(package().join(kind))
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        files.sort();
        for f in files {
            interfaces.push(Ros2Interface {
                package: "robot_msgs".into(),
                kind: kind.into(),
                name: f.file_stem().unwrap().to_string_lossy().into(),
                text: std::fs::read_to_string(&f).unwrap(),
            });
        }
    }
    NodeDescription {
        interfaces,
        ..NodeDescription::default()
    }
}

fn drive(topic: &str) -> TopicSpec {
    TopicSpec {
        topic: topic.into(),
        ty: TypeName::parse("robot_msgs/msg/Drive").unwrap(),
        qos: Qos::default(),
        field: None,
    }
}

#[test]
fn rosbags_reads_a_team_type_we_publish_with_its_own_hash_and_we_read_its() {
    let Some(python) = ferroc_testkit::python(&["zenoh", "rosbags"]) else {
        return;
    };
    let listen = support::free_port();
    let addresses = Addresses {
        part: "base".into(),
        listen: listen.clone(),
        peers: [("base".to_string(), listen.clone())].into(),
    };
    let config = ferroc_zenoh::config::config(&addresses, None).unwrap();
    let session = zenoh::open(config).wait().unwrap();
    let registry = Arc::new(interfaces::registry(&[carried()]).unwrap());
    let ours = ferroc_ros2::hash::rihs01(&registry, &drive("/drive").ty).unwrap();
    let spec = NodeSpec {
        domain: 0,
        namespace: "/".into(),
        name: "ferroc_team".into(),
    };
    let node = Ros2Node::declare(&session, Arc::clone(&registry), &spec, 0).unwrap();
    let publisher = node.publisher(drive("/drive")).unwrap();
    let received = Arc::new(Mutex::new(Vec::new()));
    let into = Arc::clone(&received);
    let _subscriber = node
        .subscriber(drive("/drive_in"), {
            // Samples arrive as CDR (the port's end decodes them at run time); here the
            // team's definitions read them back to the port's serde form.
            let registry = Arc::clone(&registry);
            move |cdr| into.lock().unwrap().push(as_json(&registry, &cdr))
        })
        .unwrap();

    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/python/ros2_team.py");
    let mut child = Command::new(&python)
        .arg(&script)
        .arg(format!("tcp/{listen}"))
        .arg(package())
        .arg("20")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // A port's value in its serde form: a library type with Drive's fields.
    let value = json!({
        "wheels": [{"speed": 1.5, "torque": -2.0}, {"speed": 0.5, "torque": 0.25}],
        "direction": {"x": 1.0, "y": 0.0, "z": 0.0},
        "mode": 1
    });
    let message = json::from_json(&registry, &drive("/drive").ty, None, &value).unwrap();
    let out = loop {
        publisher.publish(&message).unwrap();
        if child.try_wait().unwrap().is_some() {
            break child.wait_with_output().unwrap();
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    };
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let text = String::from_utf8_lossy(&out.stdout);
    let report: serde_json::Value = serde_json::from_str(text.trim()).expect("one JSON object");

    // rosbags' hash of the same definitions is ours, and it is the one in our key.
    assert_eq!(report["hash"], json!(ours), "{text}");
    let samples = report["samples"].as_array().unwrap();
    assert!(!samples.is_empty(), "{text}");
    for s in samples {
        let key = format!("0/drive/robot_msgs::msg::dds_::Drive_/{ours}");
        assert_eq!(s["key"], json!(key), "{s}");
        assert_eq!(s["wheels"], json!([[1.5, -2.0], [0.5, 0.25]]), "{s}");
        assert_eq!(s["direction"], json!([1.0, 0.0, 0.0]), "{s}");
        assert_eq!(s["mode"], json!(1), "{s}");
    }
    // Its Drive reached our subscription, decoded with the team's definitions.
    let got = received.lock().unwrap().clone();
    assert!(
        !got.is_empty(),
        "nothing arrived; rosbags sent {}",
        report["sent"]
    );
    let expected = json!({
        "wheels": [{"speed": 0.25, "torque": 1.0}, {"speed": -0.25, "torque": 2.0}],
        "direction": {"x": 0.0, "y": 1.0, "z": 0.0},
        "mode": 0
    });
    assert!(got.iter().all(|v| *v == expected), "{got:?}");
    drop(node);
    session.close().wait().unwrap();
}

/// A Drive sample's CDR as the serde form a port's value has.
fn as_json(registry: &Registry, bytes: &[u8]) -> serde_json::Value {
    let ty = drive("/drive").ty;
    let message = cdr::decode(registry, &ty, bytes).unwrap();
    json::to_json(registry, &ty, None, &message).unwrap()
}
