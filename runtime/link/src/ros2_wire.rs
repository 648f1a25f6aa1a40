//! The ROS 2 wire as the rest of a program may use it (issue 29, docs/ros2.md): which
//! ports of the program's nodes are ROS 2 topics, and how a port's value becomes its
//! topic's message (CDR) and back. Recordings use it (`ferroc_std::recording`): a
//! published port is also recorded as its topic's CDR with the message's `ros2msg`
//! schema, which ROS 2 tools read, and a player replays such a channel.
//!
//! The runtime knows no CDR: the network that speaks ROS 2 (`ferroc_zenoh::ros2`)
//! [`install`]s what does when it is made, and adds its nodes' topics when it opens
//! them ([`add_topics`]). A program without ROS 2 installs nothing: [`wire`] is `None`.
//! Process-wide, like the recording modules' other settings.

use crate::ros2::Ros2Topic;
use std::sync::{Arc, PoisonError, RwLock};

/// What turns a port's value into a ROS 2 message and back (see the module docs).
/// A port's value travels as its serde JSON, as the ROS 2 ends send it.
pub trait Ros2Wire: Send + Sync {
    /// The schema of `message` (`package/msg/Name`) as MCAP's `ros2msg` encoding holds
    /// it: its definition and those of the types it uses.
    fn schema(&self, message: &str) -> Result<String, String>;
    /// The CDR sample of `message` from a port's value (its serde JSON): all of the
    /// message, or with `field` (`linear.x`) only that field, the others zero.
    fn encode(&self, message: &str, field: Option<&str>, json: &[u8]) -> Result<Vec<u8>, String>;
    /// A port's value (serde JSON) from a CDR sample of `message`: all of it, or the
    /// one `field` the port carries. Hostile bytes are an error, never a panic.
    fn decode(&self, message: &str, field: Option<&str>, cdr: &[u8]) -> Result<Vec<u8>, String>;
}

static WIRE: RwLock<Option<Arc<dyn Ros2Wire>>> = RwLock::new(None);
static TOPICS: RwLock<Vec<Ros2Topic>> = RwLock::new(Vec::new());

/// From now on [`wire`] is `wire` (the last installed wins: a network opening its nodes
/// installs the one with the definitions they use).
pub fn install(wire: Arc<dyn Ros2Wire>) {
    *WIRE.write().unwrap_or_else(PoisonError::into_inner) = Some(wire);
}

/// The installed wire; `None` in a program that speaks no ROS 2.
pub fn wire() -> Option<Arc<dyn Ros2Wire>> {
    WIRE.read().unwrap_or_else(PoisonError::into_inner).clone()
}

/// Adds the topic ends of nodes being opened (an end already known, by its number, is
/// kept once).
pub fn add_topics<'a>(topics: impl IntoIterator<Item = &'a Ros2Topic>) {
    let mut known = TOPICS.write().unwrap_or_else(PoisonError::into_inner);
    for t in topics {
        if !known.iter().any(|k| k.id == t.id) {
            known.push(t.clone());
        }
    }
}

/// The topic the output `port` (`module/path/port`) is published on, if it is.
pub fn published(port: &str) -> Option<Ros2Topic> {
    let known = TOPICS.read().unwrap_or_else(PoisonError::into_inner);
    known
        .iter()
        .find(|t| {
            t.publish
                && port
                    .strip_prefix(t.port.0.as_str())
                    .and_then(|rest| rest.strip_prefix('/'))
                    == Some(t.port.1.as_str())
        })
        .cloned()
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
        }
    }

    #[test]
    fn only_published_ports_are_found_by_their_whole_path() {
        add_topics(&[
            topic(900, true, "robot/main/drive", "cmd"),
            topic(901, false, "robot/main/control", "enable"),
        ]);
        add_topics(&[topic(900, true, "robot/main/drive", "cmd")]);
        assert_eq!(published("robot/main/drive/cmd").map(|t| t.id), Some(900));
        assert_eq!(published("robot/main/control/enable"), None, "subscribed");
        assert_eq!(published("robot/main/drive/cmdx"), None);
        assert_eq!(published("robot/main/drivecmd"), None);
        let count = TOPICS
            .read()
            .unwrap()
            .iter()
            .filter(|t| t.id == 900)
            .count();
        assert_eq!(count, 1, "an end is kept once");
    }
}
