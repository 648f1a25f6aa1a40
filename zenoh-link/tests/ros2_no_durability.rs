//! A program built without ferroc-zenoh's feature `ros2-durability` (no zenoh-ext:
//! docs/ros2.md "Transient local") refuses a transient-local topic, publisher or
//! subscription, with a message naming the topic and saying how to get the feature,
//! and still publishes and subscribes volatile topics.
//!
//! The feature is on by default, so this file is empty in the ordinary build (and in
//! `scripts/test`); it runs in
//! `cargo test -p ferroc-zenoh --no-default-features --test ros2_no_durability`, which
//! builds Zenoh and tokio once more with other features (1.5 min on 2 cores). One Zenoh
//! session on loopback, multicast scouting off; the volatile sample goes from the
//! session's publisher to its own subscription.
#![cfg(not(feature = "ros2-durability"))]

use ferroc_ros2::def::TypeName;
use ferroc_ros2::rmw_zenoh::{Durability, Qos};
use ferroc_ros2::{cdr, Registry};
use ferroc_zenoh::ros2::{NodeSpec, Ros2Node, TopicSpec};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use zenoh::{Config, Session, Wait};

fn session() -> Session {
    let mut config = Config::default();
    for (key, value) in [
        ("mode", "\"peer\""),
        ("listen/endpoints", "[\"tcp/127.0.0.1:0\"]"),
        ("connect/endpoints", "[]"),
        ("scouting/multicast/enabled", "false"),
    ] {
        config.insert_json5(key, value).unwrap();
    }
    zenoh::open(config).wait().unwrap()
}

fn node(session: &Session) -> Ros2Node {
    let spec = NodeSpec {
        domain: 0,
        namespace: "/".into(),
        name: "plain_build".into(),
    };
    Ros2Node::declare(session, Arc::new(Registry::shipped()), &spec, 0).unwrap()
}

fn float(topic: &str, durability: Durability) -> TopicSpec {
    TopicSpec {
        topic: topic.into(),
        ty: TypeName::parse("std_msgs/msg/Float64").unwrap(),
        qos: Qos {
            durability,
            ..Qos::default()
        },
        field: None,
    }
}

/// The message says which topic, that the feature is missing, and what to do.
fn assert_refused(why: &str, what: &str) {
    assert!(why.starts_with(what), "{why}");
    assert!(
        why.contains("transient-local durability needs ferroc-zenoh's feature `ros2-durability`"),
        "{why}"
    );
    assert!(why.contains("bundle the model again"), "{why}");
}

#[test]
fn a_transient_local_topic_is_refused_with_how_to_get_the_feature() {
    let session = session();
    let node = node(&session);
    let why = node
        .publisher(float("/map", Durability::TransientLocal))
        .err()
        .expect("a transient-local publisher without the feature");
    assert_refused(&why, "cannot publish the ROS 2 topic `/map`: ");
    let why = node
        .subscriber(float("/goal", Durability::TransientLocal), |_| {})
        .err()
        .expect("a transient-local subscription without the feature");
    assert_refused(&why, "cannot subscribe to the ROS 2 topic `/goal`: ");
    session.close().wait().unwrap();
}

#[test]
fn a_volatile_topic_still_flows_without_the_feature() {
    let session = session();
    let node = node(&session);
    let received = Arc::new(Mutex::new(Vec::new()));
    let into = Arc::clone(&received);
    let _subscriber = node
        .subscriber(float("/speed", Durability::Volatile), move |bytes| {
            into.lock().unwrap().push(bytes)
        })
        .unwrap();
    let publisher = node
        .publisher(float("/speed", Durability::Volatile))
        .unwrap();
    let mut sample = cdr::HEADER.to_vec();
    sample.extend(2.5f64.to_le_bytes());
    // No deadline on the delivery itself: the test waits (up to a minute) for the one
    // sample, whatever the machine's load.
    let start = Instant::now();
    while received.lock().unwrap().is_empty() && start.elapsed() < Duration::from_secs(60) {
        publisher.publish_cdr(sample.clone()).unwrap();
        std::thread::sleep(Duration::from_millis(50));
    }
    assert_eq!(received.lock().unwrap().first(), Some(&sample));
    session.close().wait().unwrap();
}
