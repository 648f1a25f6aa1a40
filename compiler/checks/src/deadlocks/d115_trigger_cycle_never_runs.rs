//! D115 `trigger-cycle-never-runs`: Data-triggered modules that only trigger each other, with no item to start: none of them ever runs.
//!
//! The analysis (`ferroc_deadlock`) runs once for all D checks: in the pass of D101.
//! This file holds the check's identity, its explanation and how a finding reads.

use crate::CheckInfo;
use ferroc_deadlock::render::Ctx;
use ferroc_deadlock::DeadTrigger;
use ferroc_diagnostics::diagnostic::{Diagnostic, Severity};

pub static CHECK: CheckInfo = CheckInfo {
    code: "D115",
    name: "trigger-cycle-never-runs",
    severity: Severity::Warning,
    summary: "Data-triggered modules that only trigger each other, with no item to start: none of them ever runs.",
    explanation: "A module in a thread container with trigger=\"data\" runs when one of its inputs
receives data. Modules that are only fed by each other, with no periodic writer and no
initial item, wait for each other's first output forever. Nothing hangs, but nothing
runs either.

Bad:
    <thread name=\"events\" trigger=\"data\"> <module name=\"a\" .../> <module name=\"b\" .../> </thread>
    <connect from=\"r/events/a/out\" to=\"r/events/b/in\"/>
    <connect from=\"r/events/b/out\" to=\"r/events/a/in\"/>

Fix: add initial=\"1\" to one <connect> of the cycle, or feed it from a periodic thread.",
    fixtures: "compiler/checks/src/deadlocks/d115_trigger_cycle_never_runs",
};

pub fn report(cx: &Ctx<'_>, d: &DeadTrigger) -> Diagnostic {
    let names: Vec<String> = d
        .modules
        .iter()
        .map(|(m, _)| format!("`{}`", cx.app.path(*m)))
        .collect();
    let (first, span) = d.modules[0];
    let mut diag = Diagnostic::new(
        &CHECK,
        span,
        format!(
            "data-triggered modules {} only trigger each other and nothing starts them: they never run",
            names.join(", ")
        ),
    )
    .label(format!("`{}` waits for data that only the cycle produces", cx.app.path(first)));
    for (m, s) in &d.modules[1..] {
        diag = diag.secondary(*s, format!("`{}` waits here", cx.app.path(*m)));
    }
    diag.help("add initial=\"1\" to one <connect> of the cycle, or feed it from a periodic thread container")
}
