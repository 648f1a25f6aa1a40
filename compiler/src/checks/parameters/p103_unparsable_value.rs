//! P103 `unparsable-value`: A parameter value does not parse as its declared type.

use crate::checks::CheckInfo;
use crate::checks::PassContext;
use crate::diagnostic::Diagnostics;
use crate::diagnostic::Severity;
use crate::ir::ParamSource;
use crate::library::module_type::check_value;

pub static CHECK: CheckInfo = CheckInfo {
    code: "P103",
    name: "unparsable-value",
    severity: Severity::Error,
    summary: "A parameter value does not parse as its declared type.",
    explanation:
        "Values are parsed by the declared type: numbers (with optional unit), `true`/`false`,
durations (`10ms`, `PT0.04S`), arrays (`1, 2, 3`), or one of the declared `choices`.

Bad:
    <param name=\"rate\">fast</param>

Fix: write a value of the declared type (`20 Hz`).",
    pass: Some(run),
    fixtures: "parameters/p103_unparsable_value",
};

/// Parses every parameter value; raises P103, and P104/P105 for values that parse but
/// lie out of range or carry a unit of another dimension (one parse, three verdicts).
fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for (id, m) in ctx.app.modules() {
        let Some(mt) = ctx.app.module_type(ctx.libraries, id) else {
            continue;
        };
        for p in &m.params {
            let Some(decl) = mt.param(&p.name) else {
                continue;
            };
            let text = match &p.source {
                ParamSource::Inline => p.text.as_str(),
                ParamSource::Config(Ok((text, _))) => text.as_str(),
                ParamSource::Config(Err(_)) | ParamSource::Cmdline => continue,
            };
            check_value(decl, text, p.span, Some(decl.span), out);
        }
    }
}
