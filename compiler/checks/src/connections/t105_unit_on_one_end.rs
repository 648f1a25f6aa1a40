//! T105 `unit-on-one-end`: Only one end of a connection declares a unit.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};
use ferroc_model::ir::{Endpoint, PortView};
use ferroc_model::library::PortDir;

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

Fix: declare the unit on the other port: a group port in the model, a flexible port on its
`<port>`, and a port its module type declares without a unit in the instance
(`<port name=\"value\" dir=\"out\" type=\"f64\" unit=\"m\"/>` inside the `<module>`, which is
how a `ferroc_std.Constant` publishes metres). Or add an
`<allow code=\"T105\" reason=\"...\"/>`.",
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
        let (unitless, with, end) = match (a, to.unit) {
            (Some(u), None) => ((c.to_span, &to), (c.from_span, u), c.to),
            (None, Some(u)) => ((c.from_span, &from), (c.to_span, u), c.from),
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
            .help(help(ctx, end, unitless.1, with.1)),
        );
    }
}

/// Where the unit goes: a port of a module type is given one by its instance (a
/// manifest is not the user's to edit, the standard library's least of all); a group
/// port or an instance's flexible port is declared in the model.
fn help(
    ctx: &PassContext<'_>,
    end: Endpoint,
    port: &PortView<'_>,
    unit: &ferroc_values::units::Unit,
) -> String {
    let Endpoint::Port { element, port: k } = end else {
        return format!(
            "declare unit=\"{unit}\" (or the intended unit) on the group port `{}`",
            port.name
        );
    };
    let Some(mt) = ctx.app.module_type(ctx.libraries, element) else {
        return format!(
            "declare unit=\"{unit}\" (or the intended unit) on `{}`",
            port.name
        );
    };
    let instance = &ctx.app.element(element).name;
    if k as usize >= mt.ports.len() {
        let group = port.name.split('/').next().unwrap_or(port.name);
        return format!(
            "declare unit=\"{unit}\" (or the intended unit) on <port name=\"{group}\"> of `{instance}`"
        );
    }
    let dir = if port.dir == PortDir::Out {
        "out"
    } else {
        "in"
    };
    format!(
        "give `{}` a unit in this instance: <port name=\"{}\" dir=\"{dir}\" type=\"{}\" unit=\"{unit}\"/> inside <module name=\"{instance}\">",
        port.name, port.name, port.ty
    )
}
