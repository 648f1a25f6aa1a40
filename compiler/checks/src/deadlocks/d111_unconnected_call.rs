//! D111 `unconnected-call`: A synchronous call through a client that no service is connected to (fails at once under this profile).
//!
//! The analysis (`ferroc_deadlock`) runs once for all D checks: in the pass of D101.
//! This file holds the check's identity, its explanation and how a finding reads.

use crate::CheckInfo;
use ferroc_deadlock::render::Ctx;
use ferroc_deadlock::StepFinding;
use ferroc_diagnostics::diagnostic::{Diagnostic, Severity};

pub static CHECK: CheckInfo = CheckInfo {
    code: "D111",
    name: "unconnected-call",
    severity: Severity::Warning,
    summary: "A synchronous call through a client that no service is connected to (fails at once under this profile).",
    explanation: "Under profile=\"finroc\" a synchronous call through an unconnected client port does not
wait: FINROC throws NO_CONNECTION at once. The call always fails, which is rarely
intended.

Bad:
    <application name=\"a\" version=\"1\" profile=\"finroc\"> ... a module whose <client name=\"map\"/>
    is called in its activity and connected to nothing ...

Fix: connect the client to a service (<connect from=\".../map\" to=\".../get\"/>).",
    fixtures: "compiler/checks/src/deadlocks/d111_unconnected_call",
};

pub fn report(cx: &Ctx<'_>, f: &StepFinding, client: &str) -> Diagnostic {
    Diagnostic::new(
        &CHECK,
        f.site,
        format!(
            "`{}` calls through client `{client}`, which is connected to no service: under profile \"finroc\" every call fails at once",
            cx.app.path(f.module)
        ),
    )
    .label(format!("client `{client}` is not connected"))
    .secondary(f.step, "the call")
    .help(format!("connect `{client}` to a service with a <connect>"))
}
