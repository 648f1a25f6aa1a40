//! R103 `ros2-unit-convention`: A port's unit differs from the unit ROS 2 reads the
//! message field in (REP-103).

use super::Found;
use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics, Severity};
use ferroc_values::units::{describe_dimension, describe_factor, parse_unit, relate, UnitRelation};

pub static CHECK: CheckInfo = CheckInfo {
    code: "R103",
    name: "ros2-unit-convention",
    severity: Severity::Error,
    summary: "A port's unit differs from the unit ROS 2 reads the message field in (REP-103).",
    explanation: "ROS 2 messages carry SI units (REP-103): metres, radians, m/s, rad/s, seconds; a Twist's
`linear` is m/s, its `angular` rad/s, a LaserScan's ranges metres. ROS 2 sends numbers
without units, so a port in cm/s published as `Twist.linear.x` makes every ROS 2 node
drive a hundred times too fast. Ports without a unit are not judged.

Bad:
    <publish port=\"control/drive/speed\" topic=\"cmd_vel\" type=\"geometry_msgs/msg/Twist\" field=\"linear.x\"/>  <!-- f64 [cm/s] -->

Fix: give the port the unit `m/s`, or connect it through `<convert scale=\"0.01\"/>` to a
port in m/s and publish that one.",
    fixtures: "compiler/checks/src/ros2/r103_ros2_unit_convention",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for walked in super::walked_topics(ctx) {
        let (t, span, view) = (walked.topic, walked.span, &walked.port);
        for f in walked.found {
            let Found::Leaf {
                path,
                unit: Some(unit),
                expected: Some(expected),
            } = f
            else {
                continue;
            };
            let Ok(want) = parse_unit(expected) else {
                continue;
            };
            let field = match (&t.field, path.is_empty()) {
                (Some((f, _)), _) => format!("{}.{f}", short(&t.ty.0)),
                (None, true) => short(&t.ty.0).to_string(),
                (None, false) => format!("{}.{path}", short(&t.ty.0)),
            };
            let (msg, help) = match relate(&unit, &want) {
                UnitRelation::Same => continue,
                UnitRelation::Scaled(k) => (
                    format!(
                        "`{}` in `{unit}` is sent as `{field}`, which ROS 2 reads in `{want}` (REP-103)",
                        view.name
                    ),
                    format!(
                        "give the port the unit `{want}`, or connect it through <convert scale=\"{}\"/> to a port in `{want}` and publish that one",
                        describe_factor(k)
                    ),
                ),
                UnitRelation::DifferentDimension => (
                    format!(
                        "`{}` carries {} (`{unit}`), but `{field}` is {} (`{want}`, REP-103)",
                        view.name,
                        describe_dimension(&unit.dimension),
                        describe_dimension(&want.dimension)
                    ),
                    "publish the port that carries this quantity, or choose the message field that means what the port carries".to_string(),
                ),
            };
            out.push(
                Diagnostic::new(&CHECK, span, msg)
                    .label(format!("`{unit}`, ROS 2 expects `{want}`"))
                    .help(help),
            );
            break; // one finding per end: the first field in the wrong unit
        }
    }
}

/// `geometry_msgs/msg/Twist` → `Twist`.
fn short(ty: &str) -> &str {
    ty.rsplit('/').next().unwrap_or(ty)
}
