//! The model's ROS 2 nodes as the runtime opens them (issue 29, docs/ros2.md): each
//! part's `<ros2>` with its topics, the names expanded as ROS 2 expands them and each
//! topic end numbered, so that `ferroc run` and a bundle give the same ends the same
//! link numbers. External nodes (`<ros2-external>`) are only for the checks. The nodes
//! are `ferroc-ros2-node`'s type, which the run plan, the runtime and bundles share.

use super::Unsupported;
use ferroc_model::ir::{self, Application, Endpoint, ServiceRole, TopicDirection};
use ferroc_model::library::LibrarySet;
use ferroc_ros2::def::TypeName;
use ferroc_ros2::names::expand_topic_name;
use ferroc_ros2::Registry;
use ferroc_ros2::TeamFile;
use ferroc_ros2_node::{Ros2Interface, Ros2Node, Ros2Qos, Ros2Service, Ros2Topic};
use ferroc_values::types::Type;
use std::borrow::Cow;

/// The nodes of the model's parts; what cannot run yet is added to `problems`.
pub(super) fn plan_ros2(
    app: &Application,
    libs: &LibrarySet,
    problems: &mut Vec<Unsupported>,
) -> Vec<Ros2Node> {
    let (mut next_id, mut next_service) = (0, 0);
    let mut nodes = Vec::new();
    let interfaces = team_interfaces(app);
    let reg = registry(&interfaces);
    for node in app.ros2.nodes.iter().filter(|n| !n.is_external()) {
        let Some(part) = node.part else { continue };
        let (mut services, mut clients) = (Vec::new(), Vec::new());
        for s in &node.services {
            match service(app, libs, &reg, (node, s), next_service) {
                Ok(planned) if s.role == ServiceRole::Client => clients.push(planned),
                Ok(planned) => services.push(planned),
                Err(what) => problems.push(Unsupported { what, span: s.span }),
            }
            next_service += 1;
        }
        let mut topics = Vec::new();
        for t in &node.topics {
            match topic(app, libs, &reg, (node, t), next_id) {
                Ok(planned) => topics.push(planned),
                Err(what) => problems.push(Unsupported { what, span: t.span }),
            }
            next_id += 1;
        }
        nodes.push(Ros2Node {
            part: app.element(part).name.clone(),
            domain: node.domain,
            namespace: node.namespace().to_string(),
            name: node.name.0.clone(),
            topics,
            services,
            clients,
            interfaces: interfaces.clone(),
        });
    }
    nodes
}

/// The definitions of the model's own packages (`<ros2-interfaces>`), which every node
/// carries to the runtime (checked by R109 before any plan is made).
fn team_interfaces(app: &Application) -> Vec<Ros2Interface> {
    let mut out = Vec::new();
    for i in &app.ros2.interfaces {
        for f in i.files.iter().flatten() {
            out.push(Ros2Interface {
                package: i.package.0.clone(),
                kind: f.kind.to_string(),
                name: f.name.clone(),
                text: f.text.clone(),
            });
        }
    }
    out
}

/// The shipped packages with `team`'s definitions.
fn registry(team: &[Ros2Interface]) -> Cow<'static, Registry> {
    if team.is_empty() {
        return Cow::Borrowed(Registry::shipped_shared());
    }
    let files = team.iter().map(|i| TeamFile {
        package: &i.package,
        kind: &i.kind,
        name: &i.name,
        text: &i.text,
        file: &i.name,
    });
    Cow::Owned(Registry::shipped_with(files).0)
}

/// The one field of `message` a port of type `port` carries when the port is a single
/// value and the message a wrapper of one field (`f64` as `std_msgs/msg/Float64`, as
/// check R102 accepts it): the runtime then fills that field alone.
fn only_field(reg: &Registry, message: &str, port: &Type) -> Option<String> {
    if matches!(port, Type::Named(..) | Type::Timestamp | Type::Duration) {
        return None;
    }
    let name = TypeName::parse(message)?;
    match reg.message(&name)?.fields.as_slice() {
        [only] => Some(only.name.clone()),
        _ => None,
    }
}

/// One `<service>` or `<client>` of `node`, numbered `id`: the module's service or
/// client, the service name expanded as ROS 2 expands it, and the field a single-value
/// request or response fills.
fn service(
    app: &Application,
    libs: &LibrarySet,
    reg: &Registry,
    (node, s): (&ir::Ros2Node, &ir::Ros2Service),
    id: u32,
) -> Result<Ros2Service, String> {
    let Some((endpoint, _)) = s.port else {
        return Err("the service of this ROS 2 end does not resolve".into());
    };
    let Endpoint::Port { element, .. } = endpoint else {
        return Err("the service of this ROS 2 end is not a module's".into());
    };
    let view = app
        .view(libs, endpoint)
        .ok_or("the service of this ROS 2 end does not resolve")?;
    let name = expand_topic_name(&s.name.0, &node.name.0, node.namespace())
        .map_err(|why| format!("ROS 2 refuses the service name `{}`: {why}", s.name.0))?;
    let module_type = app.module_type(libs, element);
    let response = module_type.and_then(|mt| s.role.response(mt, view.name));
    Ok(Ros2Service {
        id,
        port: (app.path(element), view.name.to_string()),
        name,
        service: s.ty.0.clone(),
        request_field: only_field(reg, &format!("{}_Request", s.ty.0), view.ty),
        response_field: response.and_then(|r| only_field(reg, &format!("{}_Response", s.ty.0), r)),
    })
}

/// One topic end of `node`, numbered `id`.
fn topic(
    app: &Application,
    libs: &LibrarySet,
    reg: &Registry,
    (node, t): (&ir::Ros2Node, &ir::Ros2Topic),
    id: u32,
) -> Result<Ros2Topic, String> {
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
    Ok(Ros2Topic {
        id,
        publish: t.direction == TopicDirection::Publish,
        port: (app.path(element), view.name.to_string()),
        model_type: view.ty.to_string(),
        topic,
        message: t.ty.0.clone(),
        field: (t.field.as_ref().map(|(f, _)| f.clone()))
            .or_else(|| only_field(reg, &t.ty.0, view.ty)),
        qos: Ros2Qos {
            reliable: !t.is_best_effort(),
            transient_local: t.is_transient_local(),
            depth: t.depth.as_ref().map_or(10, |(d, _)| *d),
        },
        frame_id: t
            .frame_id
            .as_ref()
            .map(|(f, _)| f.clone())
            .unwrap_or_default(),
    })
}
