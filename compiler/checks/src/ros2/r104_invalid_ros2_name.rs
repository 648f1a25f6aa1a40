//! R104 `invalid-ros2-name`: A node name, namespace, topic or service name that ROS 2
//! refuses.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics, Severity};
use ferroc_diagnostics::source::Span;
use ferroc_ros2::names;

pub static CHECK: CheckInfo = CheckInfo {
    code: "R104",
    name: "invalid-ros2-name",
    severity: Severity::Error,
    summary: "A node name, namespace, topic or service name that ROS 2 refuses.",
    explanation: "ROS 2 refuses, when the node starts, names outside its rules
(design.ros2.org/articles/topic_and_service_names.html): a node name is letters, digits
and `_`, not starting with a digit; a namespace is absolute (`/robot1`); a topic or service
name is `/`-separated tokens of letters, digits and `_`, none starting with a digit, no
`//`, no trailing `/`, `~` only as `~/` at the start, and at most 247 characters when
expanded against the node's namespace.

Bad:
    <ros2 node=\"base-controller\">

Fix: `node=\"base_controller\"`.",
    fixtures: "compiler/checks/src/ros2/r104_invalid_ros2_name",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for node in &ctx.app.ros2.nodes {
        let (name, span) = &node.name;
        report(
            out,
            *span,
            name,
            names::validate_node_name(name),
            "node name",
        );
        if let Some((ns, span)) = &node.namespace {
            report(out, *span, ns, names::validate_namespace(ns), "namespace");
        }
        let ns = node.namespace();
        for t in &node.topics {
            let (topic, span) = &t.topic;
            let r = names::expand_topic_name(topic, name, ns).map(|_| ());
            report(out, *span, topic, r, "topic name");
        }
        for s in &node.services {
            let (service, span) = &s.name;
            let r = names::expand_topic_name(service, name, ns).map(|_| ());
            report(out, *span, service, r, "service name");
        }
    }
}

fn report(out: &mut Diagnostics, span: Span, text: &str, r: Result<(), String>, what: &str) {
    if let Err(why) = r {
        out.push(
            Diagnostic::new(&CHECK, span, format!("ROS 2 refuses the {what} `{text}`: {why}"))
                .label(format!("invalid {what}"))
                .help("use letters, digits and `_` in `/`-separated parts that do not start with a digit, e.g. `cmd_vel` or `/robot1/cmd_vel`"),
        );
    }
}
