//! R108 `ros2-service-mismatch`: A module's service (or client) does not match the ROS 2
//! service type it is offered (or called) as: its request type against the service's
//! request message, its response type against the response message.

use super::{Found, Target, Walk};
use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics, Severity};
use ferroc_diagnostics::source::Span;
use ferroc_model::ir::{Endpoint, Ros2Service, ServiceRole, TopicDirection};
use ferroc_ros2::def::TypeName;
use ferroc_values::types::Type;

pub static CHECK: CheckInfo = CheckInfo {
    code: "R108",
    name: "ros2-service-mismatch",
    severity: Severity::Error,
    summary: "A module's service or client does not match the ROS 2 service type it is offered or called as.",
    explanation: "A `<service>` offers a module's service as a ROS 2 service, a `<client>` lets a
module's client call one. The request travels as the service type's request message
(`Name_Request`), the answer as its response message (`Name_Response`), each matched as a
topic's port is (R102): a library type with the message's fields in order, or a single
value for a message of one field (`bool` as std_srvs/srv/SetBool's request `data`).
Anything else would be encoded wrongly: ROS 2's client would receive garbage or wait
for an answer that never decodes.

Bad:
    <service port=\"control/drive/reset\" name=\"~/reset\" type=\"std_srvs/srv/SetBool\"/>  <!-- bool → bool -->

Fix: answer with a library type of SetBool's response fields (`success: bool`,
`message: string`), or name a service type whose messages match the module's.",
    fixtures: "compiler/checks/src/ros2/r108_ros2_service_mismatch",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for node in ctx.app.ros2.nodes.iter().filter(|n| !n.is_external()) {
        for s in &node.services {
            check(ctx, s, out);
        }
    }
}

/// The first mismatch of the request and of the response of `s`, each reported.
fn check(ctx: &PassContext<'_>, s: &Ros2Service, out: &mut Diagnostics) {
    let reg = super::registry(ctx);
    let Some(srv) = TypeName::parse(&s.ty.0).filter(|n| n.kind == "srv") else {
        return; // R101 reports it
    };
    let Some(service) = reg.service(&srv) else {
        return;
    };
    let Some((ep @ Endpoint::Port { element, .. }, span)) = s.port else {
        return;
    };
    let Some(view) = ctx.app.view(ctx.libraries, ep) else {
        return;
    };
    let Some(mt) = ctx.app.module_type(ctx.libraries, element) else {
        return;
    };
    let response = s.role.response(mt, view.name);
    // The server reads the request and writes the response; a client the reverse.
    let (request_dir, response_dir) = match s.role {
        ServiceRole::Server => (TopicDirection::Subscribe, TopicDirection::Publish),
        ServiceRole::Client => (TopicDirection::Publish, TopicDirection::Subscribe),
    };
    let mut report = |what: &str, ty: &Type, message, dir| {
        if let Some(why) = first_mismatch(ctx, ty, message, dir) {
            out.push(mismatch(span, view.name, what, ty, message, &why));
        }
    };
    report("request", view.ty, &service.request, request_dir);
    if let Some(response) = response {
        report("response", response, &service.response, response_dir);
    }
}

/// Why `ty` does not carry `message` (at which field), if it does not.
fn first_mismatch(
    ctx: &PassContext<'_>,
    ty: &Type,
    message: &ferroc_ros2::def::Message,
    dir: TopicDirection,
) -> Option<String> {
    let mut walk = Walk::new(ctx, dir);
    walk.target(ty, None, &Target::Message(message));
    walk.found.into_iter().find_map(|f| match f {
        Found::Mismatch { path, why } if path.is_empty() => Some(why),
        Found::Mismatch { path, why } => Some(format!("at `{path}`: {why}")),
        Found::Leaf { .. } => None,
    })
}

fn mismatch(
    span: Span,
    port: &str,
    what: &str,
    ty: &Type,
    message: &ferroc_ros2::def::Message,
    why: &str,
) -> Diagnostic {
    Diagnostic::new(
        &CHECK,
        span,
        format!(
            "the {what} of `{port}` (`{ty}`) does not match `{}`: {why}",
            message.name
        ),
    )
    .label(format!("{what} differs from the service's"))
    .help(format!(
        "give the {what} a library type whose fields match `{}`'s in names, order and widths \
         (a single value for a message of one field), or name a service type that matches \
         the module's",
        message.name
    ))
}
