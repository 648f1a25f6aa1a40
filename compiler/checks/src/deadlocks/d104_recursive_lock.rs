//! D104 `recursive-lock`: A thread takes a lock it already holds (possibly through an inline service).
//!
//! The analysis (`ferroc_deadlock`) runs once for all D checks: in the pass of D101.
//! This file holds the check's identity, its explanation and how a finding reads.

use crate::CheckInfo;
use ferroc_deadlock::render::Ctx;
use ferroc_deadlock::StepFinding;
use ferroc_diagnostics::diagnostic::{Diagnostic, Severity};
use ferroc_diagnostics::source::Span;

pub static CHECK: CheckInfo = CheckInfo {
    code: "D104",
    name: "recursive-lock",
    severity: Severity::Error,
    summary: "A thread takes a lock it already holds (possibly through an inline service).",
    explanation: "A mutex that is not recursive blocks a thread that takes it a second time: the thread
waits for itself. This happens most easily through a service declared
executes=\"caller\": its body runs inline in the caller's thread, with the caller's locks
still held.

Bad:
    <activity><lock slot=\"l\"/><call client=\"self\"/></activity>
    <service name=\"s\" request=\"f64\" response=\"f64\" executes=\"caller\"><lock slot=\"l\"/></service>

Fix: release the lock before the call, or declare the resource kind=\"recursive\"
(<resource name=\"l\" kind=\"recursive\"/>) if re-entry is intended.",
    fixtures: "compiler/checks/src/deadlocks/d104_recursive_lock",
};

/// Lock `lock` taken again at `f.step` while held since `first`.
pub fn report(cx: &Ctx<'_>, f: &StepFinding, lock: u32, first: Span) -> Diagnostic {
    let name = &cx.m.locks[lock as usize].name;
    let inline = match f.inline {
        Some((m, s)) => format!(
            " in inline service `{}`.{}",
            cx.app.path(m),
            cx.app
                .module_type(cx.libs, m)
                .map_or("?", |mt| mt.services[s].name.as_str())
        ),
        None => String::new(),
    };
    Diagnostic::new(
        &CHECK,
        f.site,
        format!(
            "deadlock: {} takes lock `{name}` again{inline} while `{}` {} holds it",
            cx.thread(f.ec),
            cx.app.path(f.root),
            f.activity
        ),
    )
    .label(format!("`{name}` is taken a second time by the same thread"))
    .secondary(first, format!("`{name}` is first taken here"))
    .secondary(f.step, "the second lock step")
    .help(format!(
        "release `{name}` before the call, or declare <resource name=\"{name}\" kind=\"recursive\"/> if re-entry is intended"
    ))
}
