//! A part's ROS 2 node on rmw_zenoh's wire, seen by clients we did not write: Python
//! `eclipse-zenoh` for the session and `rosbags` (its own ROS 2 Jazzy definitions, RIHS01
//! hashes and CDR) for the messages (`tests/python/ros2_peer.py`). It must see the
//! node's, publisher's and subscription's liveliness tokens, receive our Twist on the
//! key rmw_zenoh uses with the values we sent and rmw_zenoh's attachment, and its Twist,
//! published on the key it builds from its own hash, must reach our subscription.
//!
//! Loopback only, multicast scouting off. Without a Python that has `zenoh` and
//! `rosbags` the test skips visibly (ferroc-testkit).

mod support;

use ferroc_ros2::def::TypeName;
use ferroc_ros2::rmw_zenoh::Qos;
use ferroc_ros2::serde_cdr::{self, Shape};
use ferroc_ros2::{json, Registry};
use ferroc_runtime::link::transport::Addresses;
use ferroc_zenoh::ros2::{NodeSpec, Ros2Node, TopicSpec};
use std::path::Path;
use std::process::Command;
use std::sync::{Arc, Mutex};
use zenoh::Wait;

fn twist(topic: &str, field: Option<&str>) -> TopicSpec {
    TopicSpec {
        topic: topic.into(),
        ty: TypeName::parse("geometry_msgs/msg/Twist").unwrap(),
        qos: Qos::default(),
        field: field.map(str::to_string),
    }
}

#[test]
fn a_ros2_peer_sees_our_node_receives_our_twist_and_feeds_our_input() {
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
    let registry = Arc::new(Registry::shipped());
    let node = NodeSpec {
        domain: 0,
        namespace: "/".into(),
        name: "ferroc_base".into(),
    };
    let node = Ros2Node::declare(&session, registry, &node, 0).unwrap();
    let publisher = node.publisher(twist("/cmd_vel", None)).unwrap();
    let received = Arc::new(Mutex::new(Vec::new()));
    let into = Arc::clone(&received);
    let _subscriber = node
        .subscriber(twist("/cmd_vel_in", Some("linear.x")), move |v| {
            into.lock().unwrap().push(v)
        })
        .unwrap();

    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/python/ros2_peer.py");
    let mut child = Command::new(&python)
        .arg(&script)
        .args([format!("tcp/{listen}").as_str(), "20"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // A port's value in its serde form: a library type with Twist's fields.
    let value = serde_json::json!({
        "linear": {"x": 0.5, "y": 0.0, "z": 0.0},
        "angular": {"x": 0.0, "y": 0.0, "z": -0.25}
    });
    let twist_type = TypeName::parse("geometry_msgs/msg/Twist").unwrap();
    let message = json::from_json(&Registry::shipped(), &twist_type, None, &value).unwrap();
    let out = loop {
        publisher.publish(&message).unwrap();
        if let Some(_status) = child.try_wait().unwrap() {
            break child.wait_with_output().unwrap();
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    };
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let text = String::from_utf8_lossy(&out.stdout);
    let report: serde_json::Value = serde_json::from_str(text.trim()).expect("one JSON object");

    // Discovery: the node, its publisher and its subscription, as `ros2 node list` and
    // `ros2 topic list -t` read them.
    let tokens: Vec<&str> = report["tokens"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t.as_str().unwrap())
        .collect();
    let zid = session.zid().to_string();
    let hash = report["hash"].as_str().unwrap();
    let dds = "geometry_msgs::msg::dds_::Twist_";
    let expect = [
        format!("@ros2_lv/0/{zid}/0/0/NN/%/%/ferroc_base"),
        format!("@ros2_lv/0/{zid}/0/1/MP/%/%/ferroc_base/%cmd_vel/{dds}/{hash}/::,10:,:,:,,"),
        format!("@ros2_lv/0/{zid}/0/2/MS/%/%/ferroc_base/%cmd_vel_in/{dds}/{hash}/::,10:,:,:,,"),
    ];
    for e in &expect {
        assert!(tokens.contains(&e.as_str()), "{e} not among {tokens:#?}");
    }

    // Our Twist, on rmw_zenoh's key with rosbags' own hash, deserialised by rosbags.
    let samples = report["samples"].as_array().unwrap();
    assert!(samples.len() >= 3, "{text}");
    let mut last_sequence = 0;
    for s in samples {
        assert_eq!(s["key"], format!("0/cmd_vel/{dds}/{hash}"), "{s}");
        assert_eq!(s["linear"], serde_json::json!([0.5, 0.0, 0.0]), "{s}");
        assert_eq!(s["angular"], serde_json::json!([0.0, 0.0, -0.25]), "{s}");
        let attachment = s["attachment"].as_str().unwrap();
        assert_eq!(attachment.len(), 66, "33 bytes: {s}");
        let sequence = i64::from_str_radix(&attachment[..2], 16).unwrap();
        assert!(sequence > last_sequence, "sequence numbers count up: {s}");
        last_sequence = sequence;
        assert_eq!(&attachment[32..34], "10", "the GID's length: {s}");
    }

    // Its Twist reached our input (the port carries linear.x).
    let got = received.lock().unwrap().clone();
    assert!(
        !got.is_empty(),
        "nothing arrived; rosbags sent {}",
        report["sent"]
    );
    let reg = Registry::shipped();
    let linear_x = Shape::new(&reg, &twist_type, Some("linear.x")).unwrap();
    let got: Vec<f64> = (got.iter())
        .map(|cdr| serde_cdr::from_cdr(&linear_x, cdr).unwrap())
        .collect();
    assert!(got.iter().all(|v| *v == 0.75), "{got:?}");
    drop(node);
    session.close().wait().unwrap();
}
