//! P110 `value-without-unit`: A number for a parameter that has a unit is written without one.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};
use ferroc_model::ir::ParamSource;
use ferroc_values::types::Type;
use ferroc_values::values::split_number;

pub static CHECK: CheckInfo = CheckInfo {
    code: "P110",
    name: "value-without-unit",
    severity: Severity::Warning,
    summary: "A number for a parameter that has a unit is written without one.",
    explanation:
        "A parameter declared with a unit (`unit=\"m/s\"`) takes a bare number in that unit, so
`1.5` for a speed means 1.5 m/s. That is right only if the writer knew the declared unit:
`1.5` meant as km/h, or `40` meant as centimetres for a parameter in metres, passes every
other check. A value that names its unit is converted (`15 cm` for a parameter in `m`)
and checked for its dimension (P105), so the unit is worth writing. The FINROC front end
warns the same way for a config value linked to a parameter with a unit (F106); config
files are FINROC's format, judged there (`ferroc check` on the FINROC application), so
this check reads only the values a model writes itself.

Bad:
    <param name=\"max_velocity\">0.3</param>        <!-- declared unit=\"m/s\" -->

Fix:
    <param name=\"max_velocity\">0.3 m/s</param>",
    fixtures: "compiler/checks/src/parameters/p110_value_without_unit",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for (id, m) in ctx.app.modules() {
        let Some(mt) = ctx.app.module_type(ctx.libraries, id) else {
            continue;
        };
        for p in &m.params {
            let Some(decl) = mt.param(&p.name) else {
                continue;
            };
            let Some(unit) = &decl.unit else { continue };
            if !is_number(&decl.ty) {
                continue;
            }
            let ParamSource::Inline = p.source else {
                continue;
            };
            let text = p.text.as_str();
            if !bare(text) {
                continue;
            }
            let written = text.trim();
            out.push(
                Diagnostic::new(
                    &CHECK,
                    p.span,
                    format!(
                        "`{written}` has no unit, but `{}` is measured in `{unit}`",
                        p.name
                    ),
                )
                .label(format!("a bare number, read as `{written} {unit}`"))
                .secondary(decl.span, format!("declared in `{unit}` here"))
                .help(format!(
                    "write the unit: `{written} {unit}` (or the unit meant, e.g. another of the same dimension)"
                )),
            );
        }
    }
}

/// Numbers, and arrays or sequences of numbers (a unit written once at the end applies
/// to every element).
fn is_number(ty: &Type) -> bool {
    match ty {
        Type::Int { .. } | Type::Float { .. } => true,
        Type::Array(elem, _) | Type::Seq(elem) => is_number(elem),
        _ => false,
    }
}

/// Whether the value is one or more numbers with no unit anywhere.
fn bare(text: &str) -> bool {
    let items: Vec<&str> = text
        .split([',', ' ', '\t', '\n', ';'])
        .filter(|s| !s.trim().is_empty())
        .collect();
    !items.is_empty()
        && items.iter().all(|i| {
            let (number, unit) = split_number(i);
            !number.is_empty() && unit.is_empty() && number.parse::<f64>().is_ok()
        })
}
