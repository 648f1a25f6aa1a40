//! D116 `lock-level-violation`: A lock taken while holding a lock whose declared level is not higher (lock hierarchy).
//!
//! The analysis (`ferroc_deadlock`) runs once for all D checks: in the pass of D101.
//! This file holds the check's identity, its explanation and how a finding reads.

use crate::CheckInfo;
use ferroc_deadlock::render::Ctx;
use ferroc_deadlock::StepFinding;
use ferroc_diagnostics::diagnostic::{Diagnostic, Severity};
use ferroc_diagnostics::source::Span;

pub static CHECK: CheckInfo = CheckInfo {
    code: "D116",
    name: "lock-level-violation",
    severity: Severity::Warning,
    summary:
        "A lock taken while holding a lock whose declared level is not higher (lock hierarchy).",
    explanation:
        "Resources may declare a level (<resource name=\"map\" level=\"10\"/>). A lock hierarchy
(Williams, C++ Concurrency in Action §3.2.5) only takes a lock while holding locks of
strictly higher levels; then no lock-order cycle can exist. ferroc reports every nested
acquisition that breaks the declared hierarchy, even when no cycle exists yet.

Bad:
    <resource name=\"hi\" level=\"10\"/> <resource name=\"lo\" level=\"5\"/>
    <activity><lock slot=\"lo\"/><lock slot=\"hi\"/></activity>

Fix: take the higher-level lock first, or correct the levels.",
    fixtures: "compiler/checks/src/deadlocks/d116_lock_level_violation",
};

pub fn report(
    cx: &Ctx<'_>,
    f: &StepFinding,
    lock: u32,
    outer: u32,
    outer_site: Span,
) -> Diagnostic {
    let (l, o) = (&cx.m.locks[lock as usize], &cx.m.locks[outer as usize]);
    let level = |x: &ferroc_deadlock::Lock| x.level.map_or("?".into(), |v| v.to_string());
    let mut d = Diagnostic::new(
        &CHECK,
        f.site,
        format!(
            "`{}` takes lock `{}` (level {}) while holding `{}` (level {}): the declared hierarchy needs a strictly lower level",
            cx.app.path(f.module),
            l.name,
            level(l),
            o.name,
            level(o)
        ),
    )
    .label(format!("`{}` taken here", l.name))
    .secondary(outer_site, format!("`{}` is held since here", o.name))
    .secondary(f.step, "the lock step");
    for decl in [l, o] {
        if let Some(s) = decl.span {
            d = d.secondary(s, format!("`{}` has level {}", decl.name, level(decl)));
        }
    }
    d.help(format!(
        "take `{}` before `{}`, or correct the levels",
        l.name, o.name
    ))
}
