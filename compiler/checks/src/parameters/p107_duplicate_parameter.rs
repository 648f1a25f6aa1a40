//! P107 `duplicate-parameter`: The same parameter is set twice on one module.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};

pub static CHECK: CheckInfo = CheckInfo {
    code: "P107",
    name: "duplicate-parameter",
    severity: Severity::Error,
    summary: "The same parameter is set twice on one module.",
    explanation:
        "Two `<param>` elements with the same name leave the reader guessing which applies.

Bad:
    <param name=\"rate\">10 Hz</param>
    <param name=\"rate\">20 Hz</param>

Fix: keep one.",
    fixtures: "compiler/checks/src/parameters/p107_duplicate_parameter",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for (_, m) in ctx.app.modules() {
        for (i, p) in m.params.iter().enumerate() {
            if let Some(first) = m.params[..i].iter().find(|q| q.name == p.name) {
                out.push(
                    Diagnostic::new(
                        &CHECK,
                        p.name_span,
                        format!("parameter `{}` is set twice", p.name),
                    )
                    .label("second value")
                    .secondary(first.name_span, "first value")
                    .help("keep one <param> per parameter"),
                );
            }
        }
    }
}
