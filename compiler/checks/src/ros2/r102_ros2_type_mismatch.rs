//! R102 `ros2-type-mismatch`: A port's type does not match the ROS 2 message type (or
//! field) it is published or subscribed as.

use super::Found;
use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics, Severity};
use ferroc_values::types::Type;

pub static CHECK: CheckInfo = CheckInfo {
    code: "R102",
    name: "ros2-type-mismatch",
    severity: Severity::Error,
    summary: "A port's type does not match the ROS 2 message type it is published or subscribed as.",
    explanation: "A port published or subscribed as a ROS 2 topic carries the message field by field:
a library type with the message's fields in order (names, numeric widths, fixed and
bounded arrays, nested messages), `timestamp`/`duration` for builtin_interfaces' Time and
Duration, a single value for a message of one field (std_msgs/msg/Float64), or with
`field=` one field of the message. Anything else would be encoded wrongly on the wire;
ROS 2 would see garbage or drop the sample.

Bad:
    <publish port=\"control/drive/speed\" topic=\"cmd_vel\" type=\"geometry_msgs/msg/Twist\"/>  <!-- f64 -->

Fix: `field=\"linear.x\"`, or a library type with the fields `linear` and `angular`.

A library may map one of its types to a message whose fields it does not have one for
one (`<type ros2=\"sensor_msgs/msg/Image\">`: `ferroc_std.Image` as
`sensor_msgs/msg/Image`, `ferroc_std.PointCloud` as `sensor_msgs/msg/PointCloud2`; its
crate writes and reads the message): such a port matches exactly that whole message
on a topic, nothing else.",
    fixtures: "compiler/checks/src/ros2/r102_ros2_type_mismatch",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for walked in super::walked_topics(ctx) {
        let (t, span, view) = (walked.topic, walked.span, &walked.port);
        let first = walked.found.into_iter().find_map(|f| match f {
            Found::Mismatch { path, why } => Some((path, why)),
            Found::Leaf { .. } => None,
        });
        let Some((path, why)) = first else {
            continue;
        };
        let at = if path.is_empty() {
            String::new()
        } else {
            format!(" at `{path}`")
        };
        let what = match &t.field {
            Some((f, _)) => format!("`{}.{f}`", t.ty.0),
            None => format!("`{}`", t.ty.0),
        };
        out.push(
            Diagnostic::new(
                &CHECK,
                span,
                format!(
                    "port `{}` (`{}`) does not match {what}{at}: {why}",
                    view.name, view.ty
                ),
            )
            .label("type differs from the message")
            .help(help(ctx, view.ty)),
        );
    }
}

/// The fix to suggest for a port of type `ty`.
fn help(ctx: &PassContext<'_>, ty: &Type) -> String {
    let mapped = match ty {
        Type::Named(id, _) => ctx.libraries.named_type(*id).ros2.as_deref(),
        _ => None,
    };
    match mapped {
        Some(message) => format!(
            "publish or subscribe it as the whole `{message}` (its library's mapping), or convert it in a module to a type that matches"
        ),
        None => "carry one field with field=\"…\" (e.g. `linear.x`), or give the port a library type whose fields match the message's in names, order and widths".into(),
    }
}
