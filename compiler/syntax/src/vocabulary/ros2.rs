//! The elements that make a part a ROS 2 node (issue 29, docs/ros2.md): `<ros2>` in a
//! `<part>` names the node and lists the ports it publishes, subscribes, offers and calls
//! as ROS 2 topics and services; `<ros2-external>` in the `<application>` declares a ROS 2
//! node outside the model, so the checks can match topics and QoS against it;
//! `<ros2-interfaces>` in the `<application>` adds a team's message package.

use super::AttrKind::*;
use super::{opt, req, AttrSpec, ElementSpec};

/// `reliability=` of a ROS 2 publisher or subscription (ROS 2's default: `reliable`).
pub const RELIABILITY: &[&str] = &["reliable", "best-effort"];
/// `durability=` (ROS 2's default: `volatile`).
pub const DURABILITY: &[&str] = &["volatile", "transient-local"];

/// A topic end of the model: a port, the topic, its message type, the part of the message
/// the port carries, and the QoS.
const TOPIC_ATTRS: &[AttrSpec] = &[
    req("port", Text),
    req("topic", Text),
    req("type", Text),
    opt("field", Text),
    opt("reliability", Choice(RELIABILITY)),
    opt("durability", Choice(DURABILITY)),
    opt("depth", Count),
];

/// A published topic end of the model: a topic end's attributes and the frame a type
/// its library maps to a message with a `header` writes there (`frame-id=`).
const PUBLISH_ATTRS: &[AttrSpec] = &[
    req("port", Text),
    req("topic", Text),
    req("type", Text),
    opt("field", Text),
    opt("reliability", Choice(RELIABILITY)),
    opt("durability", Choice(DURABILITY)),
    opt("depth", Count),
    opt("frame-id", Text),
];

/// A topic end of an external node: no port.
const EXTERNAL_TOPIC_ATTRS: &[AttrSpec] = &[
    req("topic", Text),
    req("type", Text),
    opt("reliability", Choice(RELIABILITY)),
    opt("durability", Choice(DURABILITY)),
    opt("depth", Count),
];

const SERVICE_ATTRS: &[AttrSpec] = &[req("port", Text), req("name", Text), req("type", Text)];

const NODE_ATTRS: &[AttrSpec] = &[
    req("node", Text),
    opt("namespace", Text),
    opt("domain", Count),
];

pub(super) const ROS2: ElementSpec = ElementSpec {
    key: "ros2",
    tag: "ros2",
    attrs: NODE_ATTRS,
    children: &[
        "ros2-publish",
        "ros2-subscribe",
        "ros2-service",
        "ros2-client",
    ],
    text: false,
};

pub(super) const ROS2_PUBLISH: ElementSpec = ElementSpec {
    key: "ros2-publish",
    tag: "publish",
    attrs: PUBLISH_ATTRS,
    children: &[],
    text: false,
};

pub(super) const ROS2_SUBSCRIBE: ElementSpec = ElementSpec {
    key: "ros2-subscribe",
    tag: "subscribe",
    attrs: TOPIC_ATTRS,
    children: &[],
    text: false,
};

pub(super) const ROS2_SERVICE: ElementSpec = ElementSpec {
    key: "ros2-service",
    tag: "service",
    attrs: SERVICE_ATTRS,
    children: &[],
    text: false,
};

pub(super) const ROS2_CLIENT: ElementSpec = ElementSpec {
    key: "ros2-client",
    tag: "client",
    attrs: SERVICE_ATTRS,
    children: &[],
    text: false,
};

pub(super) const ROS2_EXTERNAL: ElementSpec = ElementSpec {
    key: "ros2-external",
    tag: "ros2-external",
    attrs: NODE_ATTRS,
    children: &["ros2-external-publish", "ros2-external-subscribe"],
    text: false,
};

/// `<ros2-interfaces package="my_robot_msgs" path="interfaces/my_robot_msgs"/>` in the
/// `<application>`: a team's ROS 2 package, read from its folder (`msg/*.msg`,
/// `srv/*.srv`, as a ROS 2 package lays them out), beside the shipped packages.
pub(super) const ROS2_INTERFACES: ElementSpec = ElementSpec {
    key: "ros2-interfaces",
    tag: "ros2-interfaces",
    attrs: &[req("package", Ident), req("path", Text)],
    children: &[],
    text: false,
};

pub(super) const ROS2_EXTERNAL_PUBLISH: ElementSpec = ElementSpec {
    key: "ros2-external-publish",
    tag: "publish",
    attrs: EXTERNAL_TOPIC_ATTRS,
    children: &[],
    text: false,
};

pub(super) const ROS2_EXTERNAL_SUBSCRIBE: ElementSpec = ElementSpec {
    key: "ros2-external-subscribe",
    tag: "subscribe",
    attrs: EXTERNAL_TOPIC_ATTRS,
    children: &[],
    text: false,
};
