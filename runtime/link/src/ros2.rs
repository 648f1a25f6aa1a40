//! A part's ROS 2 node, as the runtime hands it to a network (issue 29, docs/ros2.md).
//!
//! A port published as a ROS 2 topic has a sending end like a link's: a step after the
//! writer that sends each new value, as its serde JSON, in a [`Frame`](super::Frame) on
//! the topic's own link number ([`link`]). A subscribed port has a receiving end that
//! publishes what arrives (JSON again) into the input. The network
//! (`ferroc_zenoh::ros2`) turns these frames into rmw_zenoh samples and back; the
//! runtime knows nothing of CDR, keys or Zenoh, only which numbers are ROS 2 ends.

/// Link numbers of data links stay below this; ROS 2 end `k` travels on
/// `ROS2_LINKS + k`; calls between parts start at `calls::CALL_LINKS`, above.
pub const ROS2_LINKS: u32 = 1 << 30;

/// The link number of the ROS 2 end `id` (the plan's numbering of every `<publish>`
/// and `<subscribe>` of the model).
pub fn link(id: u32) -> u32 {
    ROS2_LINKS.saturating_add(id)
}

/// A part as a ROS 2 node, with its topics.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Ros2Node {
    /// The part (the program holding the node).
    pub part: String,
    /// `ROS_DOMAIN_ID`.
    pub domain: u32,
    /// Absolute, `/` when none.
    pub namespace: String,
    /// The node's name.
    pub name: String,
    /// Its `<publish>` and `<subscribe>` ends.
    pub topics: Vec<Ros2Topic>,
}

/// One `<publish>` or `<subscribe>` of a node.
#[derive(Clone, Debug, PartialEq)]
pub struct Ros2Topic {
    /// The link number its frames travel on ([`link`]).
    pub link: u32,
    /// `true`: the port is published as the topic; `false`: subscribed from it.
    pub publish: bool,
    /// The port: module path and port name.
    pub port: (String, String),
    /// The port's model type (its value-table key).
    pub model_type: String,
    /// The fully qualified topic (`/robot1/cmd_vel`).
    pub topic: String,
    /// The message type, `package/msg/Name`.
    pub message: String,
    /// The one field of the message the port carries (`linear.x`), if not all of it.
    pub field: Option<String>,
    /// Reliability, durability and depth.
    pub qos: Ros2Qos,
}

/// A topic end's QoS, as the model says it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Ros2Qos {
    /// Reliable (ROS 2's default), else best effort.
    pub reliable: bool,
    /// Transient local, else volatile (the default).
    pub transient_local: bool,
    /// History depth (keep last).
    pub depth: u32,
}

impl Default for Ros2Qos {
    /// rclcpp's default profile: reliable, volatile, keep last 10.
    fn default() -> Self {
        Ros2Qos {
            reliable: true,
            transient_local: false,
            depth: 10,
        }
    }
}
