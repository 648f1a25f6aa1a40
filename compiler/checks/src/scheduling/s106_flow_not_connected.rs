//! S106 `flow-not-connected`: no data path leads from a `<flow>`'s `from` to its `to`.

use crate::{CheckInfo, PassContext};
use ferroc_diagnostics::diagnostic::Diagnostic;
use ferroc_diagnostics::diagnostic::{Diagnostics, Severity};
use ferroc_schedule::latency::Latencies;

pub static CHECK: CheckInfo = CheckInfo {
    code: "S106",
    name: "flow-not-connected",
    severity: Severity::Error,
    summary: "No data path leads from a <flow>'s `from` to its `to`.",
    explanation: "A `<flow>` bounds the latency along the connections from `from` to `to`. When no
chain of data connections (through group ports, across thread containers and parts)
leads from the one module to the other, the requirement can never be met: usually a
connection is missing, the flow names the ends the wrong way round, or the path goes
through a service call (calls are not data flow). Modules that no thread container
executes are not on any path.

Bad:
    <connect from=\"robot/main/laser/scan\" to=\"robot/main/planner/scan\"/>
    <flow name=\"react\" from=\"robot/main/planner\" to=\"robot/main/laser\" max-latency=\"50ms\"/>

Fix: connect the path, or correct `from` and `to` (from the cause to the effect).",
    fixtures: "compiler/checks/src/scheduling/s106_flow_not_connected",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    let app = ctx.app;
    if app.timing.flows.is_empty() {
        return;
    }
    let schedule = ferroc_schedule::compute(app, ctx.libraries);
    let lat = Latencies::new(app, ctx.libraries, &schedule);
    for flow in &app.timing.flows {
        if lat.bound(flow).is_some() {
            continue;
        }
        let backwards = lat.bound_between(flow.to, flow.from).is_some();
        let d = Diagnostic::new(
            &CHECK,
            flow.to_span,
            format!(
                "flow `{}`: no data path leads from `{}` to `{}`",
                flow.name,
                app.path(flow.from),
                app.path(flow.to)
            ),
        )
        .label("not reachable from `from`")
        .secondary(flow.from_span, "the flow starts here");
        out.push(if backwards {
            d.help("data flows the other way: swap `from` and `to`")
        } else {
            d.help("connect the modules (an output of one, through any chain of connections, to an input of the other), or correct `from` and `to`")
        });
    }
}
