//! T112 `double-scaling`: A `<convert scale>` on a connection whose units are scaled already.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};
use ferroc_values::units::{describe_factor, relate, UnitRelation};

pub static CHECK: CheckInfo = CheckInfo {
    code: "T112",
    name: "double-scaling",
    severity: Severity::Warning,
    summary: "A `<convert scale>` on a connection whose units are scaled already.",
    explanation:
        "Between `m` and `mm` the checker already inserts the factor 1000. A `<convert scale>` on
the same connection would scale a second time.

Bad:
    <connect from=\"a/dist_m\" to=\"b/dist_mm\"><convert scale=\"1000\"/></connect>

Fix: remove the `scale`; declared units do the conversion.",
    fixtures: "compiler/checks/src/connections/t112_double_scaling",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for (c, from, to) in ctx.connections_with_ends() {
        let Some((a, b)) = super::unit_pair(ctx, c, from, to) else {
            continue;
        };
        let UnitRelation::Scaled(f) = relate(a, b) else {
            continue;
        };
        for step in &c.converts {
            if let Some((_, span)) = step.scale {
                out.push(
                    Diagnostic::new(
                        &CHECK,
                        span,
                        format!(
                            "this scale comes on top of the automatic `{a}` → `{b}` factor {}",
                            describe_factor(f)
                        ),
                    )
                    .label("second scaling")
                    .secondary(c.span, "units already scaled on this connection")
                    .help("remove `scale`; the declared units convert the value"),
                );
            }
        }
    }
}
