//! T105 `unit-on-one-end`: Only one end of a connection declares a unit.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};

pub static CHECK: CheckInfo = CheckInfo {
    code: "T105",
    name: "unit-on-one-end",
    severity: Severity::Warning,
    summary: "Only one end of a connection declares a unit.",
    explanation:
        "When one end says `m` and the other says nothing, the checker cannot tell whether the
consumer expects metres. Usually the unit-less port was declared carelessly.

Bad:
    <connect from=\"robot/main/sim/ir_front\" to=\"robot/main/dump/in/0\"/>  <!-- m → unit-less -->

Fix: declare the unit on the other port, or add an `<allow code=\"T105\" reason=\"...\"/>`.",
    fixtures: "compiler/checks/src/connections/t105_unit_on_one_end",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for (c, from, to) in ctx.connections_with_ends() {
        if !from.ty.is_numeric() || !to.ty.is_numeric() {
            continue;
        }
        // iB2C meta inputs are dimensionless by definition: a number with a unit feeding
        // one is B102's finding (it needs a converter), not a unit to declare.
        if to.role == ferroc_model::library::PortRole::Meta {
            continue;
        }
        let a = super::source_unit(ctx, c, from);
        let (unitless, with) = match (a, to.unit) {
            (Some(u), None) => ((c.to_span, &to), (c.from_span, u)),
            (None, Some(u)) => ((c.from_span, &from), (c.to_span, u)),
            _ => continue,
        };
        out.push(
            Diagnostic::new(
                &CHECK,
                unitless.0,
                format!(
                    "`{}` declares no unit, the other end is in `{}`",
                    unitless.1.name, with.1
                ),
            )
            .label("no unit")
            .secondary(with.0, format!("in `{}`", with.1))
            .help(format!(
                "declare unit=\"{}\" (or the intended unit) on `{}`",
                with.1, unitless.1.name
            )),
        );
    }
}
