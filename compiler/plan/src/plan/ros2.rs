//! The model's ROS 2 nodes as the runtime opens them (issue 29, docs/ros2.md): each
//! part's `<ros2>` with its topics, the names expanded as ROS 2 expands them and each
//! topic end numbered, so that `ferroc run` and a bundle give the same ends the same
//! link numbers. External nodes (`<ros2-external>`) are only for the checks.

use super::Unsupported;
use ferroc_diagnostics::source::Span;
use ferroc_model::ir::{Application, Endpoint, Ros2Node, Ros2Topic, ServiceRole, TopicDirection};
use ferroc_model::library::LibrarySet;
use ferroc_ros2::def::TypeName;
use ferroc_ros2::names::expand_topic_name;
use ferroc_ros2::Registry;
use ferroc_values::types::Type;

/// A part as a ROS 2 node.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedRos2Node {
    /// The part's name.
    pub part: String,
    pub domain: u32,
    /// Absolute (`/` when the model gives none).
    pub namespace: String,
    pub name: String,
    pub topics: Vec<PlannedRos2Topic>,
    pub span: Span,
}

/// One `<publish>` or `<subscribe>`.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedRos2Topic {
    /// Its number among every topic end of the model, in model order.
    pub id: u32,
    /// Published (else subscribed).
    pub publish: bool,
    /// The port: module path and port name.
    pub port: (String, String),
    /// The port's model type.
    pub ty: String,
    /// Fully qualified (`/robot1/cmd_vel`).
    pub topic: String,
    /// `package/msg/Name`.
    pub message: String,
    pub field: Option<String>,
    pub reliable: bool,
    pub transient_local: bool,
    pub depth: u32,
    pub span: Span,
}

/// The nodes of the model's parts; what cannot run yet is added to `problems`.
pub(super) fn plan_ros2(
    app: &Application,
    libs: &LibrarySet,
    problems: &mut Vec<Unsupported>,
) -> Vec<PlannedRos2Node> {
    let mut next_id = 0;
    let mut nodes = Vec::new();
    for node in app.ros2.nodes.iter().filter(|n| !n.is_external()) {
        let Some(part) = node.part else { continue };
        if let Some(s) = node.services.first() {
            let what = match s.role {
                ServiceRole::Server => "offering a service",
                ServiceRole::Client => "calling a service",
            };
            problems.push(Unsupported {
                what: format!(
                    "{what} as a ROS 2 service is checked but not run yet\n  help: \
                     remove the `<service>`/`<client>` from `<ros2>` to run the model"
                ),
                span: s.span,
            });
        }
        let mut topics = Vec::new();
        for t in &node.topics {
            match topic(app, libs, node, t, next_id) {
                Ok(planned) => topics.push(planned),
                Err(what) => problems.push(Unsupported { what, span: t.span }),
            }
            next_id += 1;
        }
        nodes.push(PlannedRos2Node {
            part: app.element(part).name.clone(),
            domain: node.domain,
            namespace: node.namespace().to_string(),
            name: node.name.0.clone(),
            topics,
            span: node.span,
        });
    }
    nodes
}

/// The one field of `message` a port of type `port` carries when the port is a single
/// value and the message a wrapper of one field (`f64` as `std_msgs/msg/Float64`, as
/// check R102 accepts it): the runtime then fills that field alone.
fn only_field(message: &str, port: &Type) -> Option<String> {
    if matches!(port, Type::Named(..) | Type::Timestamp | Type::Duration) {
        return None;
    }
    let name = TypeName::parse(message)?;
    match Registry::shipped_shared().message(&name)?.fields.as_slice() {
        [only] => Some(only.name.clone()),
        _ => None,
    }
}

/// One topic end of `node`, numbered `id`.
fn topic(
    app: &Application,
    libs: &LibrarySet,
    node: &Ros2Node,
    t: &Ros2Topic,
    id: u32,
) -> Result<PlannedRos2Topic, String> {
    let Some((endpoint, _)) = t.port else {
        return Err("the port of this ROS 2 end does not resolve".into());
    };
    let Endpoint::Port { element, .. } = endpoint else {
        return Err(
            "a ROS 2 end on a group port is checked but not run yet\n  help: name the \
             module's port behind it (`thread/module/port`)"
                .into(),
        );
    };
    let view = app
        .view(libs, endpoint)
        .ok_or("the port of this ROS 2 end does not resolve")?;
    let topic = expand_topic_name(&t.topic.0, &node.name.0, node.namespace())
        .map_err(|why| format!("ROS 2 refuses the topic name `{}`: {why}", t.topic.0))?;
    Ok(PlannedRos2Topic {
        id,
        publish: t.direction == TopicDirection::Publish,
        port: (app.path(element), view.name.to_string()),
        ty: view.ty.to_string(),
        topic,
        message: t.ty.0.clone(),
        field: (t.field.as_ref().map(|(f, _)| f.clone())).or_else(|| only_field(&t.ty.0, view.ty)),
        reliable: !t.is_best_effort(),
        transient_local: t.is_transient_local(),
        depth: t.depth.as_ref().map_or(10, |(d, _)| *d),
        span: t.span,
    })
}
