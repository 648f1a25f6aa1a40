//! S105 `flow-latency`: the latency bound of a `<flow>` exceeds its `max-latency`.

use super::{duration, EPS};
use crate::{CheckInfo, PassContext};
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics, Severity};
use ferroc_model::ir::Flow;
use ferroc_schedule::latency::{FlowBound, Hop, HopKind, Latencies};
use std::fmt::Write;

pub static CHECK: CheckInfo = CheckInfo {
    code: "S105",
    name: "flow-latency",
    severity: Severity::Error,
    summary: "The end-to-end latency bound of a <flow> exceeds its max-latency.",
    explanation:
        "`<flow name from to max-latency>` asks for a guarantee: a change at `from` reaches
`to` within `max-latency`. The compiler bounds the latency along the data path from the
start of `from` to the completion of `to` (the cheapest path if there are several):
each module's budget, plus per hop: nothing for a hop inside one thread container in
schedule order, one period for a hop against the schedule order (a broken loop edge or
`delay=\"1\"`), up to one reader period for a hop into another container (the value may
just miss the read), and capacity − 1 more reader periods through a queue. A flow whose
bound exceeds `max-latency` is reported with the path and each hop's share.

Bad:
    <part name=\"robot\">
      <thread name=\"sense\" period=\"10ms\"><module name=\"laser\" type=\"nav.Laser\"/></thread>
      <thread name=\"plan\" period=\"100ms\"><module name=\"planner\" type=\"nav.Planner\"/></thread>
    </part>
    <connect from=\"robot/sense/laser/scan\" to=\"robot/plan/planner/scan\"/>
    <flow name=\"react\" from=\"robot/sense/laser\" to=\"robot/plan/planner\" max-latency=\"50ms\"/>

Fix: shorten the period of the container that dominates (usually the reader of a
cross-container hop), run the path inside one container in schedule order, remove a
delay, shrink a queue, or relax max-latency.",
    fixtures: "compiler/checks/src/scheduling/s105_flow_latency",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    let flows = &ctx.app.timing.flows;
    if flows.is_empty() {
        return;
    }
    let schedule = ferroc_schedule::compute(ctx.app, ctx.libraries);
    let lat = Latencies::new(ctx.app, ctx.libraries, &schedule);
    for flow in flows {
        if let Some(b) = lat.bound(flow) {
            if b.total > flow.max_latency.0 * (1.0 + EPS) {
                out.push(report(ctx, flow, &b));
            }
        }
    }
}

/// What a hop adds, in words.
pub fn describe(ctx: &PassContext<'_>, hop: &Hop) -> String {
    let app = ctx.app;
    let thread = |m| {
        app.element(m)
            .thread
            .map_or(String::new(), |t| format!("`{}`", app.path(t)))
    };
    let mut s = match hop.kind {
        HopKind::InOrder => format!("in schedule order inside {}: +0", thread(hop.to)),
        HopKind::AgainstOrder { period } => format!(
            "against the schedule order inside {} (read in the next cycle): +1 period ({})",
            thread(hop.to),
            duration(period)
        ),
        HopKind::Sampled { period } => format!(
            "into another thread container {}: up to 1 reader period ({})",
            thread(hop.to),
            duration(period)
        ),
        HopKind::SenseToControl => "sense step to control step of the same module: +0".into(),
        HopKind::ControlToSense { period } => format!(
            "control step to the next cycle's sense step: +1 period ({})",
            duration(period)
        ),
    };
    if let Some(q) = hop.queue.filter(|&q| q > 1) {
        let _ = write!(s, ", queue of {q}: +{} reader periods", q - 1);
    }
    let _ = write!(s, ", budgets {}", duration(hop.exec));
    s
}

fn report(ctx: &PassContext<'_>, flow: &Flow, b: &FlowBound) -> Diagnostic {
    let app = ctx.app;
    let mut d = Diagnostic::new(
        &CHECK,
        flow.max_latency.1,
        format!(
            "flow `{}` cannot meet its max-latency of {}: its latency from `{}` to `{}` is bounded by {}",
            flow.name,
            duration(flow.max_latency.0),
            app.path(flow.from),
            app.path(flow.to),
            duration(b.total)
        ),
    )
    .label(format!("bound {}", duration(b.total)));
    let mut text = format!(
        "latency bound, hop by hop:\n  start: budget of `{}`: {}\n",
        app.path(flow.from),
        duration(b.start)
    );
    let mut worst: Option<(f64, &Hop)> = None;
    for (i, hop) in b.hops.iter().enumerate() {
        let add = hop.wait + hop.exec;
        let what = describe(ctx, hop);
        let _ = writeln!(
            text,
            "  {}. `{}` → `{}`: {what} = {}",
            i + 1,
            app.path(hop.from),
            app.path(hop.to),
            duration(add)
        );
        let span = hop
            .edge
            .as_ref()
            .and_then(|e| e.hops.last())
            .map_or(app.element(hop.to).name_span, |&c| {
                app.connections[c].to_span
            });
        d = d.secondary(span, format!("hop {}: +{} ({what})", i + 1, duration(add)));
        if worst.is_none_or(|(w, _)| add > w) {
            worst = Some((add, hop));
        }
    }
    let _ = writeln!(text, "  total: {}", duration(b.total));
    let fix = match worst {
        Some((_, hop)) => match hop.kind {
            HopKind::Sampled { .. }
            | HopKind::AgainstOrder { .. }
            | HopKind::ControlToSense { .. }
                if hop.wait > 0.0 =>
            {
                let t = app
                    .element(hop.to)
                    .thread
                    .map_or(String::new(), |t| app.path(t));
                format!(
                    "the largest share is waiting for `{t}`: shorten its period, or run `{}` and `{}` in one thread container in schedule order (no delay)",
                    app.path(hop.from),
                    app.path(hop.to)
                )
            }
            _ => "the budgets dominate: make the modules on the path cheaper".into(),
        },
        None => "the budget of the module dominates: make it cheaper".into(),
    };
    d.help(format!("{text}fix: {fix}, or relax max-latency"))
}
