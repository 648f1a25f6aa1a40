//! R107 `ros2-topic-without-publisher`: An input subscribes to a ROS 2 topic that nothing
//! in the model and no declared external node publishes.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics, Severity};
use ferroc_model::ir::TopicDirection;
use hashbrown::HashSet;

pub static CHECK: CheckInfo = CheckInfo {
    code: "R107",
    name: "ros2-topic-without-publisher",
    severity: Severity::Warning,
    summary: "An input subscribes to a ROS 2 topic that nothing in the model and no declared external node publishes.",
    explanation: "An input fed by a ROS 2 topic waits for its first sample. If no part of the model
publishes the topic and no `<ros2-external>` node is declared to publish it, either the
name is misspelt (ROS 2 names are case-sensitive, relative names resolve against the
node's namespace) or the publisher is outside the model and should be declared, so that
its type and QoS are checked too.

Bad:
    <subscribe port=\"nav/planner/goal\" topic=\"goal_pose\" type=\"geometry_msgs/msg/PoseStamped\"/>  <!-- in /robot1 -->

Fix: `topic=\"/goal_pose\"`, or declare the publisher:
    <ros2-external node=\"rviz2\"><publish topic=\"/goal_pose\" type=\"geometry_msgs/msg/PoseStamped\"/></ros2-external>",
    fixtures: "compiler/checks/src/ros2/r107_ros2_topic_without_publisher",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    let ends = super::topic_ends(ctx);
    let published: HashSet<(u32, &str)> = ends
        .iter()
        .filter(|e| e.topic.direction == TopicDirection::Publish)
        .map(|e| (e.node.domain, e.full.as_str()))
        .collect();
    for sub in &ends {
        if sub.node.is_external()
            || sub.topic.direction != TopicDirection::Subscribe
            || published.contains(&(sub.node.domain, sub.full.as_str()))
        {
            continue;
        }
        out.push(
            Diagnostic::new(
                &CHECK,
                sub.topic.topic.1,
                format!(
                    "nothing publishes `{}`: no part of the model and no declared external node",
                    sub.full
                ),
            )
            .label("no publisher")
            .help(format!(
                "check the name, or declare the node that publishes it: <ros2-external node=\"NAME\"><publish topic=\"{}\" type=\"{}\"/></ros2-external>",
                sub.full, sub.topic.ty.0
            )),
        );
    }
}
