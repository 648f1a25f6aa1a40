//! Which ports and services of the modules a part's ROS 2 node carries (issue 29): the
//! node descriptions the builder was given ([`Builder::ros2_node`]), as the
//! inspector's [`Ros2View`]s, by module path.
//!
//! [`Builder::ros2_node`]: crate::builder::Builder::ros2_node

use super::view::{QosView, Ros2View};
use ferroc_link::ros2::{Ros2Node, Ros2Qos};
use std::collections::HashMap;

/// Every end of `nodes`, by the path of the module it belongs to, in model order.
pub(super) fn by_module(nodes: &[Ros2Node]) -> HashMap<String, Vec<Ros2View>> {
    let mut ends: HashMap<String, Vec<Ros2View>> = HashMap::new();
    for node in nodes {
        let name = node_name(node);
        let view = |port: &(String, String), role: &str, topic: &str, ty: &str| Ros2View {
            port: port.1.clone(),
            role: role.into(),
            name: topic.into(),
            r#type: ty.into(),
            field: None,
            node: name.clone(),
            domain: node.domain,
            qos: None,
        };
        for t in &node.topics {
            let role = if t.publish { "publish" } else { "subscribe" };
            let mut v = view(&t.port, role, &t.topic, &t.message);
            v.field = t.field.clone();
            v.qos = Some(qos(&t.qos));
            ends.entry(t.port.0.clone()).or_default().push(v);
        }
        let services = (node.services.iter().map(|s| (s, "service")))
            .chain(node.clients.iter().map(|c| (c, "client")));
        for (s, role) in services {
            let v = view(&s.port, role, &s.name, &s.service);
            ends.entry(s.port.0.clone()).or_default().push(v);
        }
    }
    ends
}

/// The node's fully qualified name: `/NAME` or `/NAMESPACE/NAME`.
fn node_name(node: &Ros2Node) -> String {
    let namespace = node.namespace.trim_end_matches('/');
    format!("{namespace}/{}", node.name)
}

fn qos(q: &Ros2Qos) -> QosView {
    QosView {
        reliability: if q.reliable {
            "reliable"
        } else {
            "best-effort"
        }
        .into(),
        durability: if q.transient_local {
            "transient-local"
        } else {
            "volatile"
        }
        .into(),
        depth: q.depth,
    }
}

/// One line about an end, as `ferroc inspect --list` writes it under the module:
/// `ROS 2 publish /cmd_vel (geometry_msgs/msg/Twist; reliable, volatile, depth 10) on
/// node /fragile_bot, domain 0`; a port that is one field of the message names it
/// (`std_msgs/msg/Float64.data`).
pub fn describe(end: &Ros2View) -> String {
    let field = end
        .field
        .as_deref()
        .map(|f| format!(".{f}"))
        .unwrap_or_default();
    let qos = (end.qos.as_ref())
        .map(|q| format!("; {}, {}, depth {}", q.reliability, q.durability, q.depth))
        .unwrap_or_default();
    format!(
        "ROS 2 {} {} ({}{field}{qos}) on node {}, domain {}",
        end.role, end.name, end.r#type, end.node, end.domain
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use ferroc_link::ros2::{Ros2Service, Ros2Topic};

    fn node() -> Ros2Node {
        Ros2Node {
            part: "robot".into(),
            domain: 3,
            namespace: "/robot1".into(),
            name: "bot".into(),
            topics: vec![Ros2Topic {
                id: 0,
                publish: false,
                port: ("robot/main/ctl".into(), "speed".into()),
                model_type: "f64".into(),
                topic: "/robot1/cmd_vel".into(),
                message: "geometry_msgs/msg/Twist".into(),
                field: Some("linear.x".into()),
                qos: Ros2Qos {
                    reliable: false,
                    transient_local: true,
                    depth: 1,
                },
                frame_id: String::new(),
            }],
            services: Vec::new(),
            clients: vec![Ros2Service {
                id: 0,
                port: ("robot/main/ctl".into(), "ask".into()),
                name: "/robot1/bot/enable".into(),
                service: "std_srvs/srv/SetBool".into(),
                request_field: Some("data".into()),
                response_field: None,
            }],
            interfaces: Vec::new(),
        }
    }

    #[test]
    fn topics_and_clients_are_listed_under_their_module() {
        let ends = by_module(&[node()]);
        assert_eq!(ends.len(), 1);
        let ctl = &ends["robot/main/ctl"];
        assert_eq!(
            describe(&ctl[0]),
            "ROS 2 subscribe /robot1/cmd_vel (geometry_msgs/msg/Twist.linear.x; best-effort, transient-local, depth 1) on node /robot1/bot, domain 3"
        );
        assert_eq!(
            describe(&ctl[1]),
            "ROS 2 client /robot1/bot/enable (std_srvs/srv/SetBool) on node /robot1/bot, domain 3"
        );
        assert_eq!(
            (ctl[0].port.as_str(), ctl[1].port.as_str()),
            ("speed", "ask")
        );
    }

    #[test]
    fn a_node_in_the_root_namespace_is_slash_name() {
        let mut n = node();
        n.namespace = "/".into();
        assert_eq!(node_name(&n), "/bot");
        assert!(by_module(&[]).is_empty());
    }
}
