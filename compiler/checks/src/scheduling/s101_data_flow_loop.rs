//! S101 `data-flow-loop`: A loop of data edges inside one thread container.

use crate::{CheckInfo, PassContext};
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics, Severity};
use ferroc_schedule::{self as schedule, BrokenEdge};

pub static CHECK: CheckInfo = CheckInfo {
    code: "S101",
    name: "data-flow-loop",
    severity: Severity::Warning,
    summary: "A loop of data edges inside one thread container; it is broken at one edge.",
    explanation:
        "A thread container runs its modules in a static order: every module after the modules
whose outputs it reads. A loop of connections inside one container has no such order, so
the scheduler breaks it at one edge: the module after that edge runs first and reads the
value the module before it wrote in the previous cycle. That one-cycle delay is often
unintended (a controller that reacts a cycle late), so it is reported, naming the loop
and the edge where it was broken. Sense steps run before control steps, so the usual
sensor → controller → actuator → sensor loop of sense-control modules is not a loop, and
a loop closed through an iB2C inhibition input (mutual inhibition) is expected.

Bad:
    <thread name=\"main\" period=\"10ms\">
      <module name=\"a\" type=\"ferroc_std.Scale\"/>
      <module name=\"b\" type=\"ferroc_std.Scale\"/>
    </thread>
    <connect from=\"robot/main/a/output\" to=\"robot/main/b/input\"/>
    <connect from=\"robot/main/b/output\" to=\"robot/main/a/input\"/>

Fix: if the feedback is intended, mark the edge that should deliver the previous cycle's
value with delay=\"1\"; otherwise break the loop, or run one side in another thread
container (edges leaving a container do not order it).",
    fixtures: "compiler/checks/src/scheduling/s101_data_flow_loop",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    let schedule = schedule::compute(ctx.app, ctx.libraries);
    for container in &schedule.containers {
        for broken in container.broken.iter().filter(|b| !b.inhibition) {
            out.push(report(ctx, container.thread, broken));
        }
    }
}

fn report(
    ctx: &PassContext<'_>,
    thread: ferroc_model::ir::ElementId,
    b: &BrokenEdge,
) -> Diagnostic {
    let app = ctx.app;
    let name = |s: &schedule::Step| match s.kind {
        schedule::StepKind::Update => format!("`{}`", app.path(s.module)),
        kind => format!("`{}` ({})", app.path(s.module), kind.as_str()),
    };
    let mut names: Vec<String> = b.cycle.iter().map(|(s, _)| name(s)).collect();
    names.push(name(&b.to));
    // The hop into the step that now runs first is the one the user would mark.
    let last_hop = |e: &schedule::DataEdge| e.hops.last().map(|&i| app.connections[i].to_span);
    let to_span = last_hop(&b.edge).unwrap_or(app.span);
    let mut d = Diagnostic::new(
        &CHECK,
        to_span,
        format!(
            "data-flow loop in thread container `{}`: {}",
            app.path(thread),
            names.join(" → ")
        ),
    )
    .label(format!(
        "loop broken here: {} runs first and reads {}'s value from the previous cycle",
        name(&b.to),
        name(&b.from)
    ));
    for (_, edge) in b.cycle.iter().filter(|(s, _)| *s != b.from) {
        if let Some(span) = last_hop(edge) {
            d = d.secondary(span, "part of the loop");
        }
    }
    d.help(
        "if this feedback is intended, add delay=\"1\" to this <connect>; otherwise break the \
         loop or run one of its modules in another thread container",
    )
}
