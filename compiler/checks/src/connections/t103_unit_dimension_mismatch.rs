//! T103 `unit-dimension-mismatch`: The two ends carry units of different physical dimensions.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};
use ferroc_values::units::describe_dimension;
use ferroc_values::units::{relate, UnitRelation};

pub static CHECK: CheckInfo = CheckInfo {
    code: "T103",
    name: "unit-dimension-mismatch",
    severity: Severity::Error,
    summary: "The two ends carry units of different physical dimensions.",
    explanation:
        "Units of the same dimension are scaled automatically (`m`→`mm`). Units of different
dimensions (`m` and `m/s`, `rad` and `m`) mean the connection is wrong: a distance fed into
a speed input.

Bad:
    <connect from=\"robot/main/odom/distance\" to=\"robot/main/ctrl/velocity\"/>  <!-- m → m/s -->

Fix: connect the port that carries the right quantity.",
    fixtures: "compiler/checks/src/connections/t103_unit_dimension_mismatch",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for (c, from, to) in ctx.connections_with_ends() {
        let Some((a, b)) = super::unit_pair(ctx, c, from, to) else {
            continue;
        };
        if relate(a, b) == UnitRelation::DifferentDimension {
            out.push(
                Diagnostic::new(
                    &CHECK,
                    c.to_span,
                    format!(
                        "`{a}` cannot flow into `{b}`: {} is not {}",
                        describe_dimension(&a.dimension),
                        describe_dimension(&b.dimension)
                    ),
                )
                .label(format!("expects `{b}`"))
                .secondary(c.from_span, format!("sends `{a}`"))
                .help("connect a port that carries the same physical quantity"),
            );
        }
    }
}
