//! R106 `ros2-qos-incompatible`: A subscription asks for more than a publisher of its
//! topic offers (reliability or durability).

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics, Severity};
use ferroc_model::ir::TopicDirection;
use hashbrown::HashMap;

pub static CHECK: CheckInfo = CheckInfo {
    code: "R106",
    name: "ros2-qos-incompatible",
    severity: Severity::Error,
    summary: "A subscription asks for more than a publisher of its topic offers (reliability or durability).",
    explanation: "ROS 2 matches a publisher and a subscription only when the publisher offers at least
what the subscription requests: a `reliable` subscription does not match a `best-effort`
publisher, a `transient-local` subscription does not match a `volatile` publisher. ROS 2
reports this at run time as an incompatible-QoS event, if anyone listens, and no data
flows. The pairs compared are the model's ends and those of declared external nodes.

Bad:
    <ros2-external node=\"lidar\"><publish topic=\"/scan\" type=\"sensor_msgs/msg/LaserScan\" reliability=\"best-effort\"/></ros2-external>
    <subscribe port=\"nav/planner/scan\" topic=\"/scan\" type=\"sensor_msgs/msg/LaserScan\"/>  <!-- reliable by default -->

Fix: `reliability=\"best-effort\"` on the subscription (sensor data is usually best effort).",
    fixtures: "compiler/checks/src/ros2/r106_ros2_qos_incompatible",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    let ends = super::topic_ends(ctx);
    let mut publishers: HashMap<(u32, &str), Vec<&super::TopicEnd<'_>>> = HashMap::new();
    for e in ends
        .iter()
        .filter(|e| e.topic.direction == TopicDirection::Publish)
    {
        publishers
            .entry((e.node.domain, e.full.as_str()))
            .or_default()
            .push(e);
    }
    for sub in ends
        .iter()
        .filter(|e| e.topic.direction == TopicDirection::Subscribe)
    {
        let pubs = publishers
            .get(&(sub.node.domain, sub.full.as_str()))
            .map_or(&[][..], |v| v.as_slice());
        for p in pubs {
            if sub.node.is_external() && p.node.is_external() {
                continue; // not the model's business
            }
            let s = sub.topic;
            let at = |written: Option<(bool, ferroc_diagnostics::source::Span)>| {
                written.map_or(s.topic.1, |(_, span)| span)
            };
            if !s.is_best_effort() && p.topic.is_best_effort() {
                push(
                    out,
                    at(s.best_effort),
                    sub,
                    p,
                    "a reliable subscription",
                    "a best-effort publisher",
                    "reliability=\"best-effort\" on the subscription",
                );
            }
            if s.is_transient_local() && !p.topic.is_transient_local() {
                push(out, at(s.transient_local), sub, p, "a transient-local subscription", "a volatile publisher", "durability=\"volatile\" on the subscription, or durability=\"transient-local\" on the publisher");
            }
        }
    }
}

#[allow(clippy::too_many_arguments)]
fn push(
    out: &mut Diagnostics,
    span: ferroc_diagnostics::source::Span,
    sub: &super::TopicEnd<'_>,
    publisher: &super::TopicEnd<'_>,
    wants: &str,
    offers: &str,
    help: &str,
) {
    out.push(
        Diagnostic::new(
            &CHECK,
            span,
            format!(
                "{wants} of `{}` does not match {offers} (node `{}`): ROS 2 delivers nothing",
                sub.full, publisher.node.name.0
            ),
        )
        .label("requested here")
        .secondary(publisher.topic.span, "offered here")
        .help(format!("write {help}")),
    );
}
