//! D109 `wait-never-served`: A blocking read of a queue nobody writes, or a synchronous call through a client nobody serves.
//!
//! The analysis (`ferroc_deadlock`) runs once for all D checks: in the pass of D101.
//! This file holds the check's identity, its explanation and how a finding reads.

use crate::CheckInfo;
use ferroc_deadlock::render::Ctx;
use ferroc_deadlock::{WaitId, WaitKind};
use ferroc_diagnostics::diagnostic::{Diagnostic, Severity};

pub static CHECK: CheckInfo = CheckInfo {
    code: "D109",
    name: "wait-never-served",
    severity: Severity::Error,
    summary: "A blocking read of a queue nobody writes, or a synchronous call through a client nobody serves.",
    explanation: "A blocking read without a timeout on an input that nothing feeds waits forever at the
first activation; so does a synchronous call without a timeout through a client that
is connected to no service (under the generic profile; under profile=\"finroc\" the call
fails at once instead: D111).

Bad:
    <in name=\"jobs\" type=\"i32\" read=\"blocking\"/>   <!-- and no <connect> into jobs -->

Fix: connect a writer (or a server), or give the read or call a timeout.",
    fixtures: "compiler/checks/src/deadlocks/d109_wait_never_served",
};

pub fn report(cx: &Ctx<'_>, w: WaitId) -> Diagnostic {
    let wait = &cx.m.waits[w as usize];
    let who = format!(
        "`{}` ({} {})",
        cx.app.path(wait.root),
        cx.where_(wait.ec),
        wait.activity
    );
    let (message, help) = match &wait.kind {
        WaitKind::Read { queue } => (
            format!("{who} blocks reading {}, which nothing writes: it waits forever", cx.queue(*queue)),
            "connect a writer to this input, or give the read a timeout (timeout= on the <in> or the <read> step)",
        ),
        _ => (
            format!("{who} makes a synchronous call that no service is connected to: it waits forever"),
            "connect the client to a service, or give the call a timeout",
        ),
    };
    Diagnostic::new(&CHECK, wait.site, message)
        .label(format!("waits forever here: {}", cx.step(w)))
        .secondary(wait.step_span, cx.step(w))
        .help(help)
}
