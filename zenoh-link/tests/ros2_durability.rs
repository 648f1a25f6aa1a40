//! Transient-local durability on rmw_zenoh's wire (docs/ros2.md), against clients we did
//! not write (`tests/python/ros2_durable.py`): Python `eclipse-zenoh`'s zenoh-ext
//! AdvancedSubscriber and AdvancedPublisher (what rmw_zenoh's transient-local ends are),
//! `zenoh-ros2-sdk`'s transient-local subscriber and `rosbags`' CDR.
//!
//! Fires: a Python subscriber that joins after our node published gets the last `depth`
//! values of each transient-local topic, and our transient-local subscription, declared
//! after a Python AdvancedPublisher published, gets its cached value. Silent: the same
//! late joiners get nothing of a volatile topic, either way.
//!
//! Loopback only, multicast scouting off. Without a Python that has `zenoh`,
//! `zenoh_ros2_sdk` and `rosbags` the tests skip visibly (ferroc-testkit).
#![cfg(feature = "ros2-durability")]

mod support;

use ferroc_ros2::def::TypeName;
use ferroc_ros2::rmw_zenoh::{Durability, History, Qos, Reliability};
use ferroc_ros2::Registry;
use ferroc_runtime::link::transport::Addresses;
use ferroc_zenoh::ros2::durability;
use ferroc_zenoh::ros2::{NodeSpec, Ros2Node, TopicSpec};
use serde_json::{json, Value};
use std::io::{BufRead, BufReader, Read, Write};
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use zenoh::Wait;

fn twist(topic: &str, reliability: Reliability, durability: Durability, depth: u32) -> TopicSpec {
    TopicSpec {
        topic: topic.into(),
        ty: TypeName::parse("geometry_msgs/msg/Twist").unwrap(),
        qos: Qos {
            reliability,
            durability,
            history: History::KeepLast(depth),
        },
        field: None,
    }
}

fn twist_type() -> TypeName {
    TypeName::parse("geometry_msgs/msg/Twist").unwrap()
}

fn moving(x: f64) -> ferroc_ros2::Value {
    let port =
        json!({"linear": {"x": x, "y": 0.0, "z": 0.0}, "angular": {"x": 0.0, "y": 0.0, "z": 0.0}});
    ferroc_ros2::json::from_json(Registry::shipped_shared(), &twist_type(), None, &port).unwrap()
}

/// The `linear.x` of a Twist sample's CDR (at run time the port's end decodes it).
fn linear_x(cdr: &[u8]) -> f64 {
    let reg = Registry::shipped_shared();
    let message = ferroc_ros2::cdr::decode(reg, &twist_type(), cdr).unwrap();
    let port: Value = ferroc_ros2::json::to_json(reg, &twist_type(), None, &message).unwrap();
    port["linear"]["x"].as_f64().unwrap()
}

/// The `linear.x` of each Twist a subscription received, in order.
type Got = Arc<Mutex<Vec<f64>>>;

fn subscribe(node: &Ros2Node, spec: TopicSpec) -> (ferroc_zenoh::ros2::Ros2Subscriber, Got) {
    let got = Got::default();
    let into = Arc::clone(&got);
    let subscriber = node
        .subscriber(spec, move |cdr| into.lock().unwrap().push(linear_x(&cdr)))
        .unwrap();
    (subscriber, got)
}

/// Our node publishes, a Python peer joins late; then the peer publishes and our
/// subscriptions join late. `timestamps`: the session stamps its samples (as `ferroc
/// run`'s ROS 2 session does); without (a bundle part's own session), a best-effort
/// cache numbers its samples instead.
fn late_joiners(timestamps: bool) {
    let Some(python) = ferroc_testkit::python(&["zenoh", "zenoh.ext", "zenoh_ros2_sdk", "rosbags"])
    else {
        return;
    };
    let listen = support::free_port();
    let port = listen.rsplit(':').next().unwrap().to_string();
    let addresses = Addresses {
        part: "base".into(),
        listen: listen.clone(),
        peers: [("base".to_string(), listen.clone())].into(),
    };
    let mut config = ferroc_zenoh::config::config(&addresses, None).unwrap();
    if timestamps {
        durability::session_settings(&mut config).unwrap();
    }
    let session = zenoh::open(config).wait().unwrap();
    assert_eq!(session.hlc().is_some(), timestamps);
    let registry = Arc::new(Registry::shipped());
    let spec = NodeSpec {
        domain: 0,
        namespace: "/".into(),
        name: "ferroc_base".into(),
    };
    let node = Ros2Node::declare(&session, registry, &spec, 0).unwrap();
    use Durability::{TransientLocal, Volatile};
    use Reliability::{BestEffort, Reliable};
    let publishers = [
        node.publisher(twist("/latched", Reliable, TransientLocal, 3)),
        node.publisher(twist("/latched_be", BestEffort, TransientLocal, 1)),
        node.publisher(twist("/volatile", Reliable, Volatile, 3)),
    ]
    .map(Result::unwrap);
    for x in 1..=5 {
        for p in &publishers {
            p.publish(&moving(f64::from(x))).unwrap();
        }
    }

    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/python/ros2_durable.py");
    let interfaces = Path::new(env!("CARGO_MANIFEST_DIR")).join("../ros2/interfaces");
    let mut child = Command::new(&python)
        .arg(&script)
        .args([port.as_str(), interfaces.to_str().unwrap(), "20"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut out = BufReader::new(child.stdout.take().unwrap());
    let mut line = String::new();
    out.read_line(&mut line).unwrap();
    assert_eq!(line.trim(), "ready", "{}", stderr_of(&mut child));

    // The peer's AdvancedPublisher has published; our subscriptions join now.
    let (_cached, from_cache) = subscribe(&node, twist("/from_py", Reliable, TransientLocal, 1));
    let (_plain, from_plain) = subscribe(&node, twist("/from_py_volatile", Reliable, Volatile, 1));
    let deadline = Instant::now() + Duration::from_secs(15);
    while from_cache.lock().unwrap().is_empty() && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(50));
    }
    child.stdin.take().unwrap().write_all(b"done\n").unwrap();
    line.clear();
    out.read_to_string(&mut line).unwrap();
    let status = child.wait().unwrap();
    assert!(status.success(), "{}", stderr_of(&mut child));
    let report: Value = serde_json::from_str(line.trim()).expect("one JSON object");

    // Fires: the late Python subscribers get the last `depth` values, in order.
    assert_eq!(report["latched"], json!([3.0, 4.0, 5.0]), "{report}");
    assert_eq!(report["latched_be"], json!([5.0]), "{report}");
    // zenoh-ros2-sdk 0.1.8 asks the cache for 3 with Zenoh's default consolidation,
    // which keeps the newest reply of each key: all three come back on the topic's key,
    // so it hands over the newest alone (rmw_zenoh's AdvancedSubscriber, like
    // eclipse-zenoh's above, asks without consolidation and gets all three).
    assert_eq!(report["sdk_latched"], json!([5.0]), "{report}");
    // and our late subscription the peer's cached value.
    assert_eq!(*from_cache.lock().unwrap(), [7.5]);
    // Silent: nothing of a volatile topic reaches a late joiner, either way.
    assert_eq!(report["volatile"], json!([]), "{report}");
    assert_eq!(report["sdk_volatile"], json!([]), "{report}");
    assert!(from_plain.lock().unwrap().is_empty());
    drop(publishers);
    drop(node);
    session.close().wait().unwrap();
}

fn stderr_of(child: &mut std::process::Child) -> String {
    let mut text = String::new();
    if let Some(mut e) = child.stderr.take() {
        let _ = e.read_to_string(&mut text);
    }
    text
}

#[test]
fn late_joiners_get_a_transient_local_topic_s_last_values_and_nothing_of_a_volatile_one() {
    late_joiners(true);
}

#[test]
fn a_session_without_time_stamps_keeps_its_cache_by_sequence_number() {
    late_joiners(false);
}
