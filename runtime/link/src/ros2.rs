//! A part's ROS 2 node, as the runtime hands it to a network (issue 29, docs/ros2.md).
//!
//! A port published as a ROS 2 topic has a sending end like a link's: a step after the
//! writer that sends each new value, as the message's CDR written straight from the
//! value (`Codec::ros2_encode`, [`topic_shape`]), in a [`Frame`](super::Frame) on the
//! topic's own link number ([`link`]). A subscribed port has a receiving end that
//! decodes what arrives (CDR again) into the input. The network
//! (`ferroc_zenoh::ros2`) sends these frames as rmw_zenoh samples (key, attachment)
//! and hands over the samples it receives; the runtime knows nothing of keys or Zenoh,
//! only which numbers are ROS 2 ends and what their messages are.
//!
//! A module's service offered as a ROS 2 service has a stand-in client, as for a call
//! from another part (`calls`), whose requests and answers travel as the CDR of the
//! service's messages ([`ServiceMessages`]) on the service's two link numbers
//! ([`request_link`], [`answer_link`]).

use ferroc_ros2::def::TypeName;
use ferroc_ros2::serde_cdr::Shape;
use ferroc_ros2::Registry;

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

/// What the values of a topic end are on the wire: its message type of the shipped
/// definitions, all of it or the one field the port carries.
pub fn topic_shape(topic: &Ros2Topic) -> Result<Shape<'static>, String> {
    let ty = TypeName::parse(&topic.message)
        .filter(|t| t.kind == "msg")
        .ok_or_else(|| format!("`{}` is not a ROS 2 message type", topic.message))?;
    Shape::new(Registry::shipped_shared(), &ty, topic.field.as_deref())
}

/// The request and response messages of a ROS 2 service end, as its calls carry them.
#[derive(Debug)]
pub struct ServiceMessages {
    /// The request message (or its one field).
    pub request: Shape<'static>,
    /// The response message (or its one field).
    pub response: Shape<'static>,
}

impl ServiceMessages {
    /// The messages of `service`'s type (`pkg/srv/Name_Request`, `…_Response`), with
    /// the one field a single-value request or response fills.
    pub fn new(service: &Ros2Service) -> Result<Self, String> {
        let ty = TypeName::parse(&service.service)
            .filter(|t| t.kind == "srv")
            .ok_or_else(|| format!("`{}` is not a ROS 2 service type", service.service))?;
        let message =
            |suffix: &str| TypeName::new(&ty.package, &ty.kind, &format!("{}_{suffix}", ty.name));
        let reg = Registry::shipped_shared();
        Ok(ServiceMessages {
            request: Shape::new(reg, &message("Request"), service.request_field.as_deref())?,
            response: Shape::new(reg, &message("Response"), service.response_field.as_deref())?,
        })
    }

    /// The request's shape, else the response's.
    pub fn of(&self, request: bool) -> &Shape<'static> {
        if request {
            &self.request
        } else {
            &self.response
        }
    }
}
