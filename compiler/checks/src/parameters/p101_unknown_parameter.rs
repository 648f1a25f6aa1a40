//! P101 `unknown-parameter`: A `<param>` the module type does not declare.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::diagnostic::{did_you_mean, Diagnostic, Diagnostics};

pub static CHECK: CheckInfo = CheckInfo {
    code: "P101",
    name: "unknown-parameter",
    severity: Severity::Error,
    summary: "A `<param>` the module type does not declare.",
    explanation:
        "Parameter names come from the module type. A misspelt name would leave the real parameter
at its default.

Bad:
    <module name=\"laser\" type=\"nav.LaserDriver\"><param name=\"rte\">20 Hz</param></module>

Fix: use a declared name (the message suggests the closest).",
    fixtures: "compiler/checks/src/parameters/p101_unknown_parameter",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for (id, m) in ctx.app.modules() {
        let Some(mt) = ctx.app.module_type(ctx.libraries, id) else {
            continue;
        };
        for p in &m.params {
            if mt.param(&p.name).is_some() {
                continue;
            }
            let d = Diagnostic::new(
                &CHECK,
                p.name_span,
                format!(
                    "module type `{}` has no parameter `{}`",
                    mt.qualified, p.name
                ),
            )
            .label("unknown parameter")
            .secondary(mt.span, "module type declared here");
            out.push(
                match did_you_mean(&p.name, mt.params.iter().map(|d| d.name.as_str())) {
                    Some(s) => d.help(format!("did you mean `{s}`?")),
                    None if mt.params.is_empty() => d.help("this module type has no parameters"),
                    None => d.help(format!(
                        "its parameters are: {}",
                        mt.params
                            .iter()
                            .map(|d| d.name.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    )),
                },
            );
        }
    }
}
