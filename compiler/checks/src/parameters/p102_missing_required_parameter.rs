//! P102 `missing-required-parameter`: A required parameter has no value.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};

pub static CHECK: CheckInfo = CheckInfo {
    code: "P102",
    name: "missing-required-parameter",
    severity: Severity::Error,
    summary: "A required parameter has no value.",
    explanation: "Parameters declared `required=\"true\"` have no sensible default (a device path, a map file).

Bad:
    <module name=\"laser\" type=\"nav.LaserDriver\"/>   <!-- `device` is required -->

Fix: add `<param name=\"device\">/dev/ttyUSB0</param>`, or give it from a config file
(`config=`) or the command line (`cmdline=`).",
    fixtures: "compiler/checks/src/parameters/p102_missing_required_parameter",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for (id, m) in ctx.app.modules() {
        let Some(mt) = ctx.app.module_type(ctx.libraries, id) else {
            continue;
        };
        for decl in mt.params.iter().filter(|d| d.required) {
            if m.params.iter().any(|p| p.name == decl.name) {
                continue;
            }
            let element = ctx.app.element(id);
            let mut d = Diagnostic::new(
                &CHECK,
                element.name_span,
                format!(
                    "`{}` needs a value for its required parameter `{}`",
                    ctx.app.path(id),
                    decl.name
                ),
            )
            .label(format!("`{}` missing", decl.name))
            .secondary(decl.span, "declared required here");
            if let Some(at) = element.instantiated_at {
                d = d.secondary(at, "in this instance");
            }
            out.push(d.help(format!("add <param name=\"{}\">…</param> (or config=\"file.xml#/entry\", or cmdline=\"name\")", decl.name)));
        }
    }
}
