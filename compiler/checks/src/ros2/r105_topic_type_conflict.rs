//! R105 `topic-type-conflict`: One ROS 2 topic is used with two message types.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics, Severity};
use hashbrown::HashMap;

pub static CHECK: CheckInfo = CheckInfo {
    code: "R105",
    name: "topic-type-conflict",
    severity: Severity::Error,
    summary: "One ROS 2 topic is used with two message types.",
    explanation: "A ROS 2 topic has one message type. rmw_zenoh puts the type and its hash into the
key of every sample, so a publisher and a subscriber of different types on the same topic
never see each other: the subscriber waits forever, and `ros2 topic list` shows the topic
twice. The ends compared are the model's and those of declared external nodes, by their
fully qualified name in the same domain.

Bad:
    <publish port=\"control/drive/cmd\" topic=\"/cmd_vel\" type=\"geometry_msgs/msg/Twist\"/>
    <ros2-external node=\"driver\"><subscribe topic=\"/cmd_vel\" type=\"geometry_msgs/msg/TwistStamped\"/></ros2-external>

Fix: use one type on the topic, or two topics.",
    fixtures: "compiler/checks/src/ros2/r105_topic_type_conflict",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    let mut first = HashMap::new();
    for end in super::topic_ends(ctx) {
        let key = (end.node.domain, end.full.clone());
        let Some(seen) = first.get(&key) else {
            first.insert(key, end);
            continue;
        };
        let seen: &super::TopicEnd<'_> = seen;
        if seen.topic.ty.0 != end.topic.ty.0 {
            out.push(
                Diagnostic::new(
                    &CHECK,
                    end.topic.ty.1,
                    format!(
                        "topic `{}` is used as `{}` here and as `{}` by node `{}`",
                        end.full, end.topic.ty.0, seen.topic.ty.0, seen.node.name.0
                    ),
                )
                .label("second type")
                .secondary(seen.topic.ty.1, "first type")
                .help(format!(
                    "use `{}` on both ends, or another topic name",
                    seen.topic.ty.0
                )),
            );
        }
    }
}
