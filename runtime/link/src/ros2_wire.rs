//! The ROS 2 ends of a program as the rest of it may see them (issue 29, docs/ros2.md):
//! which ports of the program's nodes are ROS 2 topics, with the definitions their
//! messages are read in. Recordings use it (`ferroc_std::recording`): a port published
//! or subscribed as a topic is also recorded as its topic's CDR, written straight from
//! the port's value with the same code the wire uses (`Codec::ros2_encode` with the
//! end's [`topic_shape`](super::ros2::topic_shape)), under the message's `ros2msg`
//! schema, which ROS 2 tools read.
//!
//! The builder [`add_node`]s every node it declares (`Builder::ros2_node`), with the
//! node's definitions (the shipped packages and the model's own). A program without ROS
//! 2 nodes adds nothing: no port is a topic. Process-wide, like the recording modules'
//! other settings.

use crate::ros2::{node_registry, Ros2Node, Ros2Topic};
use ferroc_ros2::Registry;
use std::sync::{PoisonError, RwLock};

/// A topic end of a node, with the definitions of its node.
#[derive(Clone)]
pub struct Ros2End {
    /// The end: its port, topic, message and QoS.
    pub topic: Ros2Topic,
    /// The node's definitions ([`node_registry`]): its topic's message is among them.
    pub registry: &'static Registry,
}

impl std::fmt::Debug for Ros2End {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.topic.fmt(f)
    }
}

static ENDS: RwLock<Vec<Ros2End>> = RwLock::new(Vec::new());
/// The definitions of every node added, each once.
static DEFINITIONS: RwLock<Vec<&'static Registry>> = RwLock::new(Vec::new());

/// Adds the topic ends of `node` (an end already known, by its number, is replaced:
/// an application built again in the same process declares its nodes again).
pub fn add_node(node: &Ros2Node) -> Result<(), String> {
    let registry = node_registry(node)?;
    let mut definitions = DEFINITIONS.write().unwrap_or_else(PoisonError::into_inner);
    if !definitions.iter().any(|d| std::ptr::eq(*d, registry)) {
        definitions.push(registry);
    }
    drop(definitions);
    let mut known = ENDS.write().unwrap_or_else(PoisonError::into_inner);
    for t in &node.topics {
        known.retain(|k| k.topic.id != t.id);
        known.push(Ros2End {
            topic: t.clone(),
            registry,
        });
    }
    Ok(())
}

/// The end of the port `port` (`module/path/port`): the topic an output is published
/// on or an input subscribed from, if it is.
pub fn end_of(port: &str) -> Option<Ros2End> {
    let known = ENDS.read().unwrap_or_else(PoisonError::into_inner);
    known.iter().find(|e| is_port(&e.topic, port)).cloned()
}

/// Every end on the topic `topic` (fully qualified: `/cmd_vel`), in the order added.
pub fn ends_on(topic: &str) -> Vec<Ros2End> {
    let known = ENDS.read().unwrap_or_else(PoisonError::into_inner);
    known
        .iter()
        .filter(|e| e.topic.topic == topic)
        .cloned()
        .collect()
}

/// The definitions of the program's nodes (the shipped packages with the model's own),
/// each set once, in the order added; none in a program without ROS 2 nodes.
pub fn definitions() -> Vec<&'static Registry> {
    DEFINITIONS
        .read()
        .unwrap_or_else(PoisonError::into_inner)
        .clone()
}

/// Whether `t`'s port is `port` (`module/path/port`).
fn is_port(t: &Ros2Topic, port: &str) -> bool {
    port.strip_prefix(t.port.0.as_str())
        .and_then(|rest| rest.strip_prefix('/'))
        == Some(t.port.1.as_str())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ros2::Ros2Qos;

    fn topic(id: u32, publish: bool, module: &str, port: &str) -> Ros2Topic {
        Ros2Topic {
            id,
            publish,
            port: (module.into(), port.into()),
            model_type: "f64".into(),
            topic: format!("/t{id}"),
            message: "std_msgs/msg/Float64".into(),
            field: Some("data".into()),
            qos: Ros2Qos::default(),
            frame_id: String::new(),
        }
    }

    fn node(topics: Vec<Ros2Topic>) -> Ros2Node {
        Ros2Node {
            part: "robot".into(),
            domain: 0,
            namespace: "/".into(),
            name: "robot".into(),
            topics,
            services: vec![],
            clients: vec![],
            interfaces: vec![],
        }
    }

    #[test]
    fn published_and_subscribed_ports_are_found_by_their_whole_path() {
        add_node(&node(vec![
            topic(900, true, "robot/main/drive", "cmd"),
            topic(901, false, "robot/main/control", "enable"),
        ]))
        .unwrap();
        add_node(&node(vec![topic(900, true, "robot/main/drive", "cmd")])).unwrap();
        let found = |p: &str| end_of(p).map(|e| (e.topic.id, e.topic.publish));
        assert_eq!(found("robot/main/drive/cmd"), Some((900, true)));
        assert_eq!(found("robot/main/control/enable"), Some((901, false)));
        assert_eq!(found("robot/main/drive/cmdx"), None);
        assert_eq!(found("robot/main/drivecmd"), None);
        assert_eq!(ends_on("/t900").len(), 1, "an end is kept once");
        assert!(end_of("robot/main/drive/cmd")
            .unwrap()
            .registry
            .message(&ferroc_ros2::def::TypeName::parse("std_msgs/msg/Float64").unwrap())
            .is_some());
    }
}
