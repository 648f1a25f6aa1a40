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
use ferroc_ros2::{Registry, TeamFile};
use std::collections::BTreeSet;
use std::sync::Mutex;

/// Link numbers of data links stay below this; ROS 2 end `k` travels on
/// `ROS2_LINKS + k`; calls between parts start at `calls::CALL_LINKS`, above.
pub const ROS2_LINKS: u32 = 1 << 30;

/// The link number of the ROS 2 end `id` (the plan's numbering of every `<publish>`
/// and `<subscribe>` of the model).
pub fn link(id: u32) -> u32 {
    ROS2_LINKS.saturating_add(id)
}

/// The name of the receiving end of the subscribed ROS 2 end `id` (the builder's
/// stand-in module whose output `out` feeds the subscribing input): what a recorder of
/// the input connects to.
pub fn subscriber_end(id: u32) -> String {
    format!("ros2 {} in", link(id))
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

/// The message packages `interfaces` (a model's `<ros2-interfaces>`, carried by its
/// nodes) make with the shipped ones. The checks (R109) refused bad definitions before
/// the run; one that still does not read (a plan written by hand) is an error naming
/// the file, line and column.
pub fn team_registry<'i>(
    interfaces: impl IntoIterator<Item = &'i Ros2Interface>,
) -> Result<Registry, String> {
    let mut seen = BTreeSet::new();
    let files: Vec<TeamFile<'_>> = interfaces
        .into_iter()
        // Every node of a model carries the model's packages: read each file once.
        .filter(|i| seen.insert((&i.package, &i.kind, &i.name)))
        .map(|i| TeamFile {
            package: &i.package,
            kind: &i.kind,
            name: &i.name,
            text: &i.text,
            file: &i.name,
        })
        .collect();
    if files.is_empty() {
        return Ok(Registry::shipped_shared().clone());
    }
    let (registry, errors) = Registry::shipped_with(files);
    match errors.first() {
        None => Ok(registry),
        Some(e) => Err(format!(
            "a ROS 2 definition of the model does not read: {e}"
        )),
    }
}

/// The definitions `node`'s ends read, for the life of the process: the shipped ones,
/// or those with the model's own packages, made once per distinct set of them (an
/// application built again in the same process, as tests do, reuses it).
pub fn node_registry(node: &Ros2Node) -> Result<&'static Registry, String> {
    type Made = Vec<(Vec<Ros2Interface>, &'static Registry)>;
    static MADE: Mutex<Made> = Mutex::new(Vec::new());
    if node.interfaces.is_empty() {
        return Ok(Registry::shipped_shared());
    }
    let mut made = MADE.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, reg)) = made.iter().find(|(i, _)| *i == node.interfaces) {
        return Ok(reg);
    }
    let reg: &'static Registry = Box::leak(Box::new(team_registry(&node.interfaces)?));
    made.push((node.interfaces.clone(), reg));
    Ok(reg)
}

/// What the values of a topic end are on the wire: its message type of `reg` (a node's
/// definitions, [`node_registry`]), all of it or the one field the port carries.
pub fn topic_shape(topic: &Ros2Topic, reg: &'static Registry) -> Result<Shape<'static>, String> {
    let ty = TypeName::parse(&topic.message)
        .filter(|t| t.kind == "msg")
        .ok_or_else(|| format!("`{}` is not a ROS 2 message type", topic.message))?;
    Shape::new(reg, &ty, topic.field.as_deref())
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
    pub fn new(service: &Ros2Service, reg: &'static Registry) -> Result<Self, String> {
        let ty = TypeName::parse(&service.service)
            .filter(|t| t.kind == "srv")
            .ok_or_else(|| format!("`{}` is not a ROS 2 service type", service.service))?;
        let message =
            |suffix: &str| TypeName::new(&ty.package, &ty.kind, &format!("{}_{suffix}", ty.name));
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

#[cfg(test)]
mod tests {
    use super::*;

    fn node(text: &str) -> Ros2Node {
        Ros2Node {
            interfaces: vec![Ros2Interface {
                package: "robot_msgs".into(),
                kind: "msg".into(),
                name: "Wheel".into(),
                text: text.into(),
            }],
            ..Ros2Node::default()
        }
    }

    fn wheel_topic() -> Ros2Topic {
        Ros2Topic {
            id: 0,
            publish: true,
            port: ("base".into(), "speed".into()),
            model_type: "f64".into(),
            topic: "/wheel".into(),
            message: "robot_msgs/msg/Wheel".into(),
            field: Some("axis.x".into()),
            qos: Ros2Qos::default(),
            frame_id: String::new(),
        }
    }

    #[test]
    fn a_node_s_team_types_reach_its_ends_once_per_set_of_definitions() {
        let wheel = node("float64 speed\ngeometry_msgs/Vector3 axis\n");
        let reg = node_registry(&wheel).unwrap();
        assert!(topic_shape(&wheel_topic(), reg).is_ok());
        assert!(std::ptr::eq(reg, node_registry(&wheel.clone()).unwrap()));
        // The tricky non-case: a node without team packages reads the shipped ones,
        // where the team's type does not exist.
        let plain = node_registry(&Ros2Node::default()).unwrap();
        assert!(std::ptr::eq(plain, Registry::shipped_shared()));
        assert!(topic_shape(&wheel_topic(), plain).is_err());
    }

    #[test]
    fn a_team_definition_that_does_not_read_is_an_error_naming_its_file() {
        let why = node_registry(&node("float64[<=x] ranges\n")).unwrap_err();
        assert!(why.contains("Wheel:1:"), "{why}");
    }
}
