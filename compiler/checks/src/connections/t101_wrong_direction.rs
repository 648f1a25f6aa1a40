//! T101 `wrong-direction`: A connection goes from something that does not emit to something that does not accept.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};

pub static CHECK: CheckInfo = CheckInfo {
    code: "T101",
    name: "wrong-direction",
    severity: Severity::Error,
    summary:
        "A connection goes from something that does not emit to something that does not accept.",
    explanation:
        "Data flows from an output (or a group's input, seen from inside) to an input (or a group's
output, seen from inside). Connecting two inputs or two outputs is a mistake in the path or
in the direction of the `<connect>`.

Bad:
    <connect from=\"robot/main/controller/velocity_in\" to=\"robot/main/motor/speed\"/>

Fix: swap `from` and `to`, or correct the port name.",
    fixtures: "compiler/checks/src/connections/t101_wrong_direction",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for (c, from, to) in ctx.connections_with_ends() {
        if !super::emits(c, c.from, from) {
            out.push(
                Diagnostic::new(
                    &CHECK,
                    c.from_span,
                    format!(
                        "`{}` does not send data: it is an input here",
                        ctx.sources.text(c.from_span)
                    ),
                )
                .label("`from` must be an output (or a group input, seen from inside the group)")
                .secondary(from.span, "declared here")
                .help(if super::emits(c, c.to, to) {
                    "swap `from` and `to`"
                } else {
                    "connect from an output port"
                }),
            );
        } else if !super::accepts(c, c.to, to) {
            out.push(
                Diagnostic::new(
                    &CHECK,
                    c.to_span,
                    format!(
                        "`{}` does not accept data: it is an output here",
                        ctx.sources.text(c.to_span)
                    ),
                )
                .label("`to` must be an input (or a group output, seen from inside the group)")
                .secondary(to.span, "declared here")
                .help("connect to an input port"),
            );
        }
    }
}
