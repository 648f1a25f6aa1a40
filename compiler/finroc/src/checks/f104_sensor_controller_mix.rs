//! F104 `sensor-controller-mix`: sensor data into a controller port, or the reverse.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "F104",
    name: "sensor-controller-mix",
    severity: Severity::Warning,
    summary:
        "An edge carries sensor data into a controller port, or controller data into a sensor port.",
    explanation: "FINROC's sense-control components keep two flows apart: sensor data travels
through `Sensor Output` → `Sensor Input` (the sense tasks, run first), controller data
through `Controller Output` → `Controller Input` (the control tasks). The scheduler
orders tasks by these interfaces: inside the sense set it ignores edges into
controller interfaces, inside the control set edges into sensor interfaces. An edge
that crosses the two flows is therefore not ordered by the scheduler (the value may be
a cycle old) and usually means a port was picked from the wrong interface.

Bad:
    <edge src=\"Robot/Sensor Output/Pose\" dest=\"Odometry/Controller Input/Pose\"/>

Fix: connect sensor outputs to sensor inputs and controller outputs to controller
inputs; declare the port in the right interface.",
    fixtures: "compiler/finroc/src/checks/f104_sensor_controller_mix",
};

use super::{Context, Facts};
use crate::finstructable::EdgeEnd;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};

/// `Some(true)` for a sensor interface, `Some(false)` for a controller interface.
fn class(end: &EdgeEnd) -> Option<bool> {
    let n = end.segments.len();
    let interface = end.segments.get(n.checked_sub(2)?)?;
    match interface.as_str() {
        "Sensor Input" | "Sensor Output" => Some(true),
        "Controller Input" | "Controller Output" => Some(false),
        _ => None,
    }
}

pub fn check(ctx: &Context<'_>, facts: &Facts<'_>, out: &mut Diagnostics) {
    for (i, edge) in ctx.doc.edges.iter().enumerate() {
        if facts.duplicate_of.contains_key(&i) {
            continue; // reported once, as the duplicate it is (F103)
        }
        let (Some(s), Some(d)) = (class(&edge.src), class(&edge.dest)) else {
            continue;
        };
        if s == d {
            continue;
        }
        let name = |sensor| if sensor { "sensor" } else { "controller" };
        out.push(
            Diagnostic::new(
                &CHECK,
                edge.dest.raw.span,
                format!(
                    "{} data from `{}` goes into a {} port",
                    name(s),
                    edge.src.path(),
                    name(d)
                ),
            )
            .label(format!("a {} interface", name(d)))
            .secondary(edge.src.raw.span, format!("a {} interface", name(s)))
            .help(format!(
                "connect it to the {} interface of the receiver, or move the port there",
                if s {
                    "Sensor Input"
                } else {
                    "Controller Input"
                }
            )),
        );
    }
}
