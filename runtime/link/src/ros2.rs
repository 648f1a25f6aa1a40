//! A part's ROS 2 node, as the runtime hands it to a network (issue 29, docs/ros2.md).
//!
//! A port published as a ROS 2 topic has a sending end like a link's: a step after the
//! writer that sends each new value, as its serde JSON, in a [`Frame`](super::Frame) on
//! the topic's own link number ([`link`]). A subscribed port has a receiving end that
//! publishes what arrives (JSON again) into the input. The network
//! (`ferroc_zenoh::ros2`) turns these frames into rmw_zenoh samples and back; the
//! runtime knows nothing of CDR, keys or Zenoh, only which numbers are ROS 2 ends.
//!
//! A module's service offered as a ROS 2 service has a stand-in client, as for a call
//! from another part (`calls`), whose requests and answers travel as JSON on the
//! service's two link numbers ([`request_link`], [`answer_link`]).

/// Link numbers of data links stay below this; ROS 2 end `k` travels on
/// `ROS2_LINKS + k`; calls between parts start at `calls::CALL_LINKS`, above.
pub const ROS2_LINKS: u32 = 1 << 30;

/// The link number of the ROS 2 end `id` (the plan's numbering of every `<publish>`
/// and `<subscribe>` of the model).
pub fn link(id: u32) -> u32 {
    ROS2_LINKS.saturating_add(id)
}

/// ROS 2 service ends travel above the topic ends: service `k`'s requests on
/// `ROS2_SERVICES + 2k`, its answers on the number after.
pub const ROS2_SERVICES: u32 = ROS2_LINKS + (1 << 29);

/// The link number of the requests of ROS 2 service end `id` (the plan's numbering of
/// every `<service>` of the model).
pub fn request_link(id: u32) -> u32 {
    ROS2_SERVICES.saturating_add(id.saturating_mul(2))
}

/// The link number of the answers of ROS 2 service end `id`.
pub fn answer_link(id: u32) -> u32 {
    request_link(id).saturating_add(1)
}

/// The node's description, shared with the plan, the run plan and bundles
/// (`ferroc-ros2-node`): one type in every layer.
pub use ferroc_ros2_node::{Ros2Interface, Ros2Node, Ros2Qos, Ros2Service, Ros2Topic};
