//! R101 `invalid-ros2-end`: A ROS 2 topic or service end names an unknown type or field,
//! or a port of the wrong kind.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics, Severity};
use ferroc_model::ir::{Endpoint, Ros2Service, Ros2Topic, ServiceRole, Spanned, TopicDirection};
use ferroc_model::library::{PortDir, PortRole};
use ferroc_ros2::def::TypeName;
use ferroc_values::types::Type;

pub static CHECK: CheckInfo = CheckInfo {
    code: "R101",
    name: "invalid-ros2-end",
    severity: Severity::Error,
    summary: "A ROS 2 topic or service end names an unknown type or field, or a port of the wrong kind.",
    explanation: "`type=` of a `<publish>` or `<subscribe>` names a message type of the shipped ROS 2
packages (`package/msg/Name`: std_msgs, builtin_interfaces, geometry_msgs, sensor_msgs,
nav_msgs), `field=` a field of it (dotted through nested messages), and `port=` an output
for `<publish>`, an input for `<subscribe>`. A `<service>` names a module's service and a
service type (`package/srv/Name`), a `<client>` a module's client.

Bad:
    <publish port=\"control/drive/speed\" topic=\"cmd_vel\" type=\"geometry_msgs/msg/Twist\" field=\"linear.v\"/>

Fix: `field=\"linear.x\"` (Vector3 has x, y, z).

`frame-id=` on a `<publish>` names the `header.frame_id` of a port type its library
maps to a whole message with a header (`ferroc_std.Image` as `sensor_msgs/msg/Image`);
anywhere else no header would carry it, which is reported too.",
    fixtures: "compiler/checks/src/ros2/r101_invalid_ros2_end",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    let reg = super::registry(ctx);
    for node in &ctx.app.ros2.nodes {
        for t in &node.topics {
            if let Err((span, why)) = super::target(reg, t) {
                out.push(
                    Diagnostic::new(&CHECK, span, why)
                        .label("unknown")
                        .help("name a type of the shipped packages (e.g. `geometry_msgs/msg/Twist`) or of a package the model adds with <ros2-interfaces>, and one of its fields; docs/ros2.md lists them"),
                );
            }
            let want = match t.direction {
                TopicDirection::Publish => PortDir::Out,
                TopicDirection::Subscribe => PortDir::In,
            };
            if let Some((ep, span)) = &t.port {
                port_kind(ctx, *ep, *span, want, None, out);
            }
            frame(ctx, t, out);
        }
        for s in &node.services {
            service(ctx, s, out);
        }
    }
}

/// Reports a `frame-id=` that no header would carry: the port's type is not one its
/// library maps to the whole message (`<type ros2=…>`), or that message has no `header`.
fn frame(ctx: &PassContext<'_>, t: &Ros2Topic, out: &mut Diagnostics) {
    let (Some((_, span)), Some((ep, _))) = (&t.frame_id, &t.port) else {
        return;
    };
    let Some(view) = ctx.app.view(ctx.libraries, *ep) else {
        return;
    };
    let mapped = match view.ty {
        Type::Named(id, _) => ctx.libraries.named_type(*id).ros2.as_deref(),
        _ => None,
    };
    let has_header = |m: &str| {
        let reg = super::registry(ctx);
        (TypeName::parse(m).and_then(|n| reg.message(&n)))
            .is_some_and(|msg| msg.fields.iter().any(|f| f.name == "header"))
    };
    let writes = t.field.is_none() && mapped.is_some_and(|m| m == t.ty.0 && has_header(m));
    if !writes {
        out.push(
            Diagnostic::new(
                &CHECK,
                *span,
                format!(
                    "`frame-id=` has no effect here: a port of type `{}` as `{}` writes no header",
                    view.ty,
                    match &t.field {
                        Some((f, _)) => format!("{}.{f}", t.ty.0),
                        None => t.ty.0.clone(),
                    }
                ),
            )
            .label("written nowhere")
            .help("frame-id= names the header.frame_id of a type its library maps to a whole message with a header (ferroc_std.Image as sensor_msgs/msg/Image, PointCloud as PointCloud2); a library type matching a message field by field carries its header itself"),
        );
    }
}

fn service(ctx: &PassContext<'_>, s: &Ros2Service, out: &mut Diagnostics) {
    let (text, span) = &s.ty;
    let known = TypeName::parse(text)
        .filter(|n| n.kind == "srv")
        .is_some_and(|n| super::registry(ctx).service(&n).is_some());
    if !known {
        out.push(
            Diagnostic::new(&CHECK, *span, format!("no service type `{text}` is known"))
                .label("unknown")
                .help("name a service type `package/srv/Name`, e.g. `std_srvs/srv/Trigger`"),
        );
    }
    let role = match s.role {
        ServiceRole::Server => PortRole::Service,
        ServiceRole::Client => PortRole::Client,
    };
    if let Some((ep, span)) = &s.port {
        let dir = match s.role {
            ServiceRole::Server => PortDir::In,
            ServiceRole::Client => PortDir::Out,
        };
        port_kind(ctx, *ep, *span, dir, Some(role), out);
    }
}

/// Reports a port that is not of the direction (and role) the end needs.
fn port_kind(
    ctx: &PassContext<'_>,
    ep: Endpoint,
    span: ferroc_diagnostics::source::Span,
    dir: PortDir,
    role: Option<PortRole>,
    out: &mut Diagnostics,
) {
    let Some(view) = ctx.app.view(ctx.libraries, ep) else {
        return;
    };
    let (ok, what, help) = match role {
        Some(PortRole::Service) => (
            view.role == PortRole::Service,
            "a service",
            "name a `<service>` of the module",
        ),
        Some(_) => (
            view.role == PortRole::Client,
            "a client",
            "name a `<client>` of the module",
        ),
        None if dir == PortDir::Out => (
            view.dir == PortDir::Out && view.role != PortRole::Client,
            "an output",
            "publish an output; to feed an input from ROS 2 use `<subscribe>`",
        ),
        None => (
            view.dir == PortDir::In && view.role != PortRole::Service,
            "an input",
            "subscribe into an input; to send an output to ROS 2 use `<publish>`",
        ),
    };
    if !ok {
        let port: Spanned<&str> = (view.name, span);
        out.push(
            Diagnostic::new(&CHECK, port.1, format!("port `{}` is not {what}", port.0))
                .label(format!("not {what}"))
                .help(help),
        );
    }
}
