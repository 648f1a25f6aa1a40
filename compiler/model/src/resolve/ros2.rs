//! `<ros2>` in a part and `<ros2-external>`: read into [`Ros2`](crate::ir::Ros2). Port
//! paths resolve relative to the part, as a `<connect>` written in the part does; what
//! the values mean (names, types, QoS pairs) is judged by the checks of area R.

use super::Resolver;
use crate::ir::*;
use ferroc_syntax::Element;

impl Resolver<'_, '_, '_> {
    /// `<ros2>` children of the part `part`.
    pub(super) fn part_ros2(&mut self, part: ElementId, e: &Element) {
        for r in e.children_named("ros2") {
            if let Some(node) = self.ros2_node(Some(part), r) {
                self.app.ros2.nodes.push(node);
            }
        }
    }

    /// `<ros2-external>` children of the application.
    pub(super) fn external_ros2(&mut self, root: &Element) {
        for r in root.children_named("ros2-external") {
            if let Some(node) = self.ros2_node(None, r) {
                self.app.ros2.nodes.push(node);
            }
        }
    }

    /// A node and its ends; `None` without `node=` (M104 reported it).
    fn ros2_node(&mut self, part: Option<ElementId>, r: &Element) -> Option<Ros2Node> {
        let mut node = Ros2Node {
            part,
            span: r.name_span,
            name: text(r, "node")?,
            namespace: text(r, "namespace"),
            domain: r.value("domain").and_then(|d| d.parse().ok()).unwrap_or(0),
            topics: Vec::new(),
            services: Vec::new(),
        };
        for c in &r.children {
            let direction = match c.name.as_str() {
                "publish" => TopicDirection::Publish,
                "subscribe" => TopicDirection::Subscribe,
                "service" | "client" => {
                    let role = if c.name == "service" {
                        ServiceRole::Server
                    } else {
                        ServiceRole::Client
                    };
                    let port = self.ros2_port(part, c);
                    if let (Some(name), Some(ty)) = (text(c, "name"), text(c, "type")) {
                        node.services.push(Ros2Service {
                            role,
                            span: c.name_span,
                            port,
                            name,
                            ty,
                        });
                    }
                    continue;
                }
                _ => continue,
            };
            let port = self.ros2_port(part, c);
            let (Some(topic), Some(ty)) = (text(c, "topic"), text(c, "type")) else {
                continue; // M104 reported the missing attribute
            };
            node.topics.push(Ros2Topic {
                direction,
                span: c.name_span,
                port,
                topic,
                ty,
                field: text(c, "field"),
                best_effort: c
                    .attr("reliability")
                    .map(|a| (a.value == "best-effort", a.value_span)),
                transient_local: c
                    .attr("durability")
                    .map(|a| (a.value == "transient-local", a.value_span)),
                depth: c
                    .attr("depth")
                    .and_then(|a| Some((a.value.trim().parse().ok()?, a.value_span))),
            });
        }
        Some(node)
    }

    /// The port a `port=` names, relative to the part (reported when it does not resolve).
    fn ros2_port(&mut self, part: Option<ElementId>, c: &Element) -> Option<Spanned<Endpoint>> {
        let part = part?;
        let a = c.attr("port")?;
        let (endpoint, _) = self.resolve_path(part, a.value, a.value_span)?;
        self.app.ros2.ports.insert(endpoint);
        Some((endpoint, a.value_span))
    }
}

fn text(e: &Element, name: &str) -> Option<Spanned<String>> {
    e.attr(name).map(|a| (a.value.to_string(), a.value_span))
}
