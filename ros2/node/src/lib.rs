//! A part's ROS 2 node as data (issue 29, docs/ros2.md): the node's name, namespace and
//! domain, and its topic ends, each with the port behind it, the message type and the
//! QoS the model gives.
//!
//! This is the one description every layer shares: the compiler's plan makes it
//! (`ferroc_plan`), the run plan carries it as JSON to a runner, a bundle's part program
//! builds it from its generated code, and the runtime hands it to the network
//! (`ferroc_link::ros2`, `ferroc_zenoh::ros2::network`). It names no crate of ours and
//! nothing of the wire (keys, CDR): those are `ferroc-ros2`'s.
//!
//! The serde form is part of the run plan's layout (version 1): its field names are the
//! ones the plan has had since ROS 2 nodes were added, and fields added later default
//! when absent, so a plan written before them still reads.

#![forbid(unsafe_code)]
#![warn(missing_docs)]

use serde::{Deserialize, Serialize};

/// A part as a ROS 2 node, with its topics.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Ros2Node {
    /// The part (the program holding the node).
    pub part: String,
    /// `ROS_DOMAIN_ID`.
    pub domain: u32,
    /// Absolute, `/` when the model gives none.
    pub namespace: String,
    /// The node's name.
    pub name: String,
    /// Its `<publish>` and `<subscribe>` ends.
    pub topics: Vec<Ros2Topic>,
    /// Its `<service>` ends (absent in plans written before services ran: none).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub services: Vec<Ros2Service>,
    /// Its `<client>` ends: modules' clients calling ROS 2 services (absent: none).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub clients: Vec<Ros2Service>,
    /// The definitions of the model's own ROS 2 packages (`<ros2-interfaces>`), which
    /// its types may name beside the shipped packages (absent: none).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub interfaces: Vec<Ros2Interface>,
}

/// One definition file of a team's ROS 2 package, as text.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Ros2Interface {
    /// The package (`my_robot_msgs`).
    pub package: String,
    /// `msg` or `srv`.
    pub kind: String,
    /// The type's name (`WheelSpeeds`).
    pub name: String,
    /// The file's text, in ROS 2's `.msg`/`.srv` format.
    pub text: String,
}

/// One `<publish>` or `<subscribe>` of a node.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Ros2Topic {
    /// Its number among every topic end of the model, in model order: a part program
    /// and `ferroc run` give the same end the same number (and so the same link).
    pub id: u32,
    /// `true`: the port is published as the topic; `false`: subscribed from it.
    pub publish: bool,
    /// The port: module path and port name.
    pub port: (String, String),
    /// The port's model type (its value-table key).
    #[serde(rename = "ty")]
    pub model_type: String,
    /// The fully qualified topic (`/robot1/cmd_vel`).
    pub topic: String,
    /// The message type, `package/msg/Name`.
    pub message: String,
    /// The one field of the message the port carries (`linear.x`), if not all of it.
    pub field: Option<String>,
    /// Reliability, durability and depth.
    #[serde(flatten)]
    pub qos: Ros2Qos,
    /// `frame-id=`: the `header.frame_id` a port type mapped to a message with a header
    /// (`ferroc_std.Image` as `sensor_msgs/msg/Image`) writes; `""` if the model names
    /// none. Absent from a plan written before it existed.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub frame_id: String,
}

/// One `<service>` (a module's service offered as a ROS 2 service) or `<client>` (a
/// module's client calling a ROS 2 service).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Ros2Service {
    /// Its number among every service and client end of the model, in model order.
    pub id: u32,
    /// The module's service or client: module path and its name.
    pub port: (String, String),
    /// The fully qualified service name (`/fragile_bot/set_enabled`).
    pub name: String,
    /// The service type, `package/srv/Name`.
    pub service: String,
    /// The one field of the request message a single-value request fills (`data` of
    /// `std_srvs/srv/SetBool`), if not all of it.
    pub request_field: Option<String>,
    /// The one field of the response message a single-value response fills, if not
    /// all of it.
    pub response_field: Option<String>,
}

/// A topic end's QoS, as the model says it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The JSON a run plan of version 1 has carried since nodes were added.
    const PLAN_V1: &str = r#"{"part":"robot","domain":0,"namespace":"/","name":"fragile_bot",
        "topics":[{"id":0,"publish":true,"port":["control/drive","cmd"],
        "ty":"crash_course.TwistOut","topic":"/cmd_vel","message":"geometry_msgs/msg/Twist",
        "field":null,"reliable":true,"transient_local":false,"depth":10}]}"#;

    fn node() -> Ros2Node {
        Ros2Node {
            part: "robot".into(),
            domain: 0,
            namespace: "/".into(),
            name: "fragile_bot".into(),
            topics: vec![Ros2Topic {
                id: 0,
                publish: true,
                port: ("control/drive".into(), "cmd".into()),
                model_type: "crash_course.TwistOut".into(),
                topic: "/cmd_vel".into(),
                message: "geometry_msgs/msg/Twist".into(),
                field: None,
                qos: Ros2Qos::default(),
                frame_id: String::new(),
            }],
            services: Vec::new(),
            clients: Vec::new(),
            interfaces: Vec::new(),
        }
    }

    #[test]
    fn a_team_s_definitions_travel_and_default_to_none() {
        let mut with = node();
        with.interfaces.push(Ros2Interface {
            package: "robot_msgs".into(),
            kind: "msg".into(),
            name: "Wheel".into(),
            text: "float64 speed\n".into(),
        });
        let text = serde_json::to_string(&with).unwrap();
        assert_eq!(serde_json::from_str::<Ros2Node>(&text).unwrap(), with);
        let plain = serde_json::to_string(&node()).unwrap();
        assert!(!plain.contains("interfaces"), "{plain}");
    }

    #[test]
    fn a_version_1_plan_s_node_reads_as_this_type() {
        let read: Ros2Node = serde_json::from_str(PLAN_V1).unwrap();
        assert_eq!(read, node());
    }

    #[test]
    fn services_travel_and_default_to_none() {
        let mut with = node();
        with.services.push(Ros2Service {
            id: 0,
            port: ("control/controller".into(), "set_enabled".into()),
            name: "/fragile_bot/set_enabled".into(),
            service: "std_srvs/srv/SetBool".into(),
            request_field: Some("data".into()),
            response_field: None,
        });
        let text = serde_json::to_string(&with).unwrap();
        assert_eq!(serde_json::from_str::<Ros2Node>(&text).unwrap(), with);
        assert!(serde_json::from_str::<Ros2Node>(PLAN_V1)
            .unwrap()
            .services
            .is_empty());
    }

    #[test]
    fn the_written_form_is_the_version_1_form() {
        let written = serde_json::to_value(node()).unwrap();
        let v1: serde_json::Value = serde_json::from_str(PLAN_V1).unwrap();
        assert_eq!(written, v1);
    }
}
