//! X101 `part-without-threads`: A part (process) has no thread container.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};
use ferroc_model::ir::ElementKind;

pub static CHECK: CheckInfo = CheckInfo {
    code: "X101",
    name: "part-without-threads",
    severity: Severity::Warning,
    summary: "A part (process) has no thread container.",
    explanation: "A part is an OS process; without a thread container it executes nothing.

Bad:
    <part name=\"station\" host=\"base-pc\"/>

Fix: add a `<thread>` with the modules it should run, or remove the part.",
    fixtures: "compiler/checks/src/deployment/x101_part_without_threads",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    let mut has_thread = vec![false; ctx.app.elements.len()];
    for e in &ctx.app.elements {
        if let (ElementKind::Thread { .. }, Some(part)) = (&e.kind, e.part) {
            has_thread[part.0 as usize] = true;
        }
    }
    for (i, e) in ctx.app.elements.iter().enumerate() {
        if matches!(e.kind, ElementKind::Part { .. }) && !has_thread[i] {
            out.push(
                Diagnostic::new(
                    &CHECK,
                    e.name_span,
                    format!(
                        "part `{}` has no thread container; its process would execute nothing",
                        e.name
                    ),
                )
                .label("no <thread> in this part")
                .help("add a <thread> holding the modules it should run, or remove the part"),
            );
        }
    }
}
