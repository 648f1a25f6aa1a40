//! D117 `latent-lock-inversion`: Locks taken in opposite orders, harmless only because the threads share a guard.
//!
//! The analysis (`ferroc_deadlock`) runs once for all D checks: in the pass of D101.
//! This file holds the check's identity, its explanation and how a finding reads.

use crate::CheckInfo;
use ferroc_deadlock::render::Ctx;
use ferroc_deadlock::{Held, Latent};
use ferroc_diagnostics::diagnostic::{Diagnostic, Severity};

pub static CHECK: CheckInfo = CheckInfo {
    code: "D117",
    name: "latent-lock-inversion",
    severity: Severity::Note,
    summary: "Locks taken in opposite orders, harmless only because the threads share a guard.",
    explanation:
        "Two activities take the same locks in opposite orders, but they cannot deadlock today:
they run on the same thread container (which serialises them), or both hold a common
outer lock. The inversion becomes a deadlock as soon as one of them moves to another
thread container or drops the outer lock.

Bad (both modules in thread container `main`):
    <activity><lock slot=\"a\"/><lock slot=\"b\"/></activity>   <!-- m1 -->
    <activity><lock slot=\"b\"/><lock slot=\"a\"/></activity>   <!-- m2 -->

Fix: take the locks in the same order everywhere.",
    fixtures: "compiler/checks/src/deadlocks/d117_latent_lock_inversion",
};

pub fn report(cx: &Ctx<'_>, l: &Latent) -> Diagnostic {
    let (w0, outer0) = l.edges[0];
    let first = &cx.m.waits[w0 as usize];
    let lock = |x: u32| &cx.m.locks[x as usize].name;
    let taken = |w: u32| match cx.m.waits[w as usize].kind {
        ferroc_deadlock::WaitKind::Lock { lock: x } => lock(x).clone(),
        _ => "?".into(),
    };
    let guard = match l.guard {
        Held::Ec(e) => format!("both run on thread container {}", cx.thread(e)),
        Held::Lock(g) => format!("both hold lock `{}` first", lock(g)),
    };
    let mut d = Diagnostic::new(
        &CHECK,
        first.site,
        format!(
            "latent lock-order inversion `{}`/`{}`: harmless only because {guard}",
            lock(outer0),
            taken(w0)
        ),
    )
    .label(format!(
        "`{}` takes `{}` while holding `{}`",
        cx.app.path(first.root),
        taken(w0),
        lock(outer0)
    ));
    for (w, outer) in &l.edges {
        let wait = &cx.m.waits[*w as usize];
        if *w != w0 {
            d = d.secondary(
                wait.site,
                format!(
                    "`{}` takes `{}` while holding `{}`",
                    cx.app.path(wait.root),
                    taken(*w),
                    lock(*outer)
                ),
            );
        }
        d = d.secondary(wait.step_span, cx.step(*w));
    }
    d.help(match l.guard {
        Held::Ec(_) => "take the locks in the same order everywhere: this becomes a deadlock as soon as one module moves to another thread container",
        Held::Lock(_) => "take the locks in the same order everywhere: this becomes a deadlock as soon as one side drops the outer lock",
    })
}
