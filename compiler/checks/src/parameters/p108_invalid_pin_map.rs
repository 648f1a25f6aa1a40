//! P108 `invalid-pin-map`: A Filter's pin map does not fit its ports.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};
use ferroc_diagnostics::source::Span;
use ferroc_model::ir::ElementKind;
use ferroc_model::library::module_type::{PortDecl, PortDir};
use ferroc_pinmap::{Dir, Entry};
use ferroc_values::units::{relate, UnitRelation};

pub static CHECK: CheckInfo = CheckInfo {
    code: "P108",
    name: "invalid-pin-map",
    severity: Severity::Error,
    summary: "A Filter's pin map does not fit its ports.",
    explanation: "`ferroc_std.Filter` copies input elements to output elements as its `map` says
(`in/0 -> out[1] * 1000 as i32`). Every pin must be a declared port of the right
direction carrying numbers, every index must lie inside its array, a whole array maps
only onto one of the same length, no output element is written twice, a conversion that
can lose data (f64 to i32) is marked with `as` and the destination's element type, and
between ports with units the scale is the units' factor (m to mm: `* 1000`). The module
applies the same rules when it is created; the check finds the mistake before a run.

Bad:
    <port name=\"in\" dir=\"in\" type=\"f64\" unit=\"m\" count=\"1\"/>
    <port name=\"out\" dir=\"out\" type=\"i32\" unit=\"mm\"/>
    <param name=\"map\">in/0 -> out</param>   <!-- no `* 1000`, no `as i32` -->

Fix:
    <param name=\"map\">in/0 -> out * 1000 as i32</param>",
    fixtures: "compiler/checks/src/parameters/p108_invalid_pin_map",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for pt in super::texts_of(ctx, "ferroc_std.Filter", "map") {
        let (id, text, mt) = (pt.id, pt.text, pt.module_type);
        let at = |r| pt.span_of(r);
        let entries = match ferroc_pinmap::parse(text) {
            Ok(e) => e,
            Err(e) => {
                out.push(
                    Diagnostic::new(
                        &CHECK,
                        at(e.span),
                        format!("the pin map does not parse: {}", e.what),
                    )
                    .label("here")
                    .help("write entries like `in/0 -> out[1] * 1000 as i32`, separated by `;`"),
                );
                continue;
            }
        };
        let ElementKind::Module(inst) = &ctx.app.element(id).kind else {
            continue;
        };
        let port = |name: &str| {
            let decl = inst.extra_ports.iter().find(|d| d.name == name)?;
            let dir = match decl.dir {
                PortDir::In => Dir::In,
                PortDir::Out => Dir::Out,
            };
            Some((dir, decl))
        };
        let types: Vec<(String, Dir, String)> = inst
            .extra_ports
            .iter()
            .filter_map(|d| {
                let (dir, decl) = port(&d.name)?;
                let ferroc_model::library::module_type::PortType::Fixed(ty) = &decl.ty else {
                    return None;
                };
                Some((d.name.clone(), dir, ty.to_string()))
            })
            .collect();
        let lookup = |name: &str| {
            types
                .iter()
                .find(|(n, _, _)| n == name)
                .map(|(_, d, t)| (*d, t.as_str()))
        };
        let misfits = ferroc_pinmap::validate(&entries, lookup);
        for f in &misfits {
            out.push(
                Diagnostic::new(&CHECK, at(f.span.clone()), f.what.clone())
                    .label("does not fit the ports")
                    .secondary(mt.span, "ferroc_std.Filter declared here")
                    .help(f.help.clone()),
            );
        }
        if !misfits.is_empty() {
            continue;
        }
        // Units: between ports with units the scale is their factor.
        for e in &entries {
            let (Some((_, a)), Some((_, b))) = (port(e.from.port), port(e.to.port)) else {
                continue;
            };
            if let Some(d) = unit_misfit(e, a, b, at(e.span.clone())) {
                out.push(d);
            }
        }
    }
}

/// Whether the scale of entry `e` (at `span`) from port `a` to port `b` is the factor
/// between their units (when both have one); the finding when not.
fn unit_misfit(e: &Entry<'_>, a: &PortDecl, b: &PortDecl, span: Span) -> Option<Diagnostic> {
    let (Some(ua), Some(ub)) = (&a.unit, &b.unit) else {
        return None;
    };
    let wanted = match relate(ua, ub) {
        UnitRelation::Same => 1.0,
        UnitRelation::Scaled(f) => f,
        UnitRelation::DifferentDimension => {
            return Some(
                Diagnostic::new(
                    &CHECK,
                    span,
                    format!(
                        "`{}` is in `{ua}`, `{}` in `{ub}`: different dimensions",
                        e.from.port, e.to.port
                    ),
                )
                .label("maps one quantity onto another")
                .secondary(b.span, format!("declared in `{ub}`"))
                .help("map a port of the same dimension, or drop a unit that is wrong"),
            );
        }
    };
    if (e.scale - wanted).abs() > 1e-9 * wanted.abs().max(1.0) {
        return Some(
            Diagnostic::new(
                &CHECK,
                span,
                format!(
                    "`{}` is in `{ua}`, `{}` in `{ub}`: the scale is {}, the units need {wanted}",
                    e.from.port, e.to.port, e.scale
                ),
            )
            .label("wrong scale for these units")
            .secondary(b.span, format!("declared in `{ub}`"))
            .help(format!("write `* {wanted}`")),
        );
    }
    None
}
