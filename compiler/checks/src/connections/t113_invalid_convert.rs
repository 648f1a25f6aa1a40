//! T113 `invalid-convert`: A `<convert>` step that cannot apply to the value.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};

pub static CHECK: CheckInfo = CheckInfo {
    code: "T113",
    name: "invalid-convert",
    severity: Severity::Error,
    summary: "A `<convert>` step that cannot apply to the value.",
    explanation: "Each `<convert>` step transforms the value: `index` takes an element of an array or
sequence, `field` a field of a library struct type, `scale`/`offset` need numbers, `to-type`
casts between numeric types. A step that does not fit the value's type, or more than four
steps, is an error.

Bad:
    <connect from=\"a/speed\" to=\"b/x\"><convert index=\"0\"/></connect>   <!-- speed is f64, not an array -->

Fix: remove the step or apply it to a port of the right type.",
    fixtures: "compiler/checks/src/connections/t113_invalid_convert",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for (c, from, to) in ctx.connections_with_ends() {
        if let Err(e) = super::flow_types(ctx, c, from, to) {
            out.push(
                Diagnostic::new(&CHECK, e.span, e.message)
                    .label("does not apply to this value")
                    .secondary(
                        from.span,
                        format!("the source `{}` is `{}`", from.name, from.ty),
                    )
                    .help("remove the step, or change it to fit the value's type"),
            );
        }
    }
}
