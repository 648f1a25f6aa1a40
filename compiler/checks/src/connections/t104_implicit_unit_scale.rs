//! T104 `implicit-unit-scale`: A scale between compatible units is inserted.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};
use ferroc_values::units::{describe_factor, relate, UnitRelation};

pub static CHECK: CheckInfo = CheckInfo {
    code: "T104",
    name: "implicit-unit-scale",
    severity: Severity::Note,
    summary: "A scale between compatible units is inserted.",
    explanation: "When both ends declare units of the same dimension but different scale (`m` and `cm`), the
value is scaled on the connection. This is correct and reported as a note so that the
factor is visible in reviews.

Example:
    <connect from=\"robot/main/sim/ir_front\" to=\"robot/main/viz/distance_cm\"/>  <!-- m → cm: ×100 -->

Nothing to fix; `--allow T104` hides these notes.",
    fixtures: "compiler/checks/src/connections/t104_implicit_unit_scale",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for (c, from, to) in ctx.connections_with_ends() {
        let Some((a, b)) = super::unit_pair(ctx, c, from, to) else {
            continue;
        };
        if let UnitRelation::Scaled(f) = relate(a, b) {
            out.push(
                Diagnostic::new(
                    &CHECK,
                    c.span,
                    format!(
                        "values are scaled by {} from `{a}` to `{b}`",
                        describe_factor(f)
                    ),
                )
                .label("scale inserted on this connection")
                .secondary(c.from_span, format!("in `{a}`"))
                .secondary(c.to_span, format!("in `{b}`"))
                .help("nothing to do; `--allow T104` hides these notes"),
            );
        }
    }
}
