//! F111 `edge-type-mismatch`: an edge between ports of different types or units.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "F111",
    name: "edge-type-mismatch",
    severity: Severity::Error,
    summary:
        "An edge connects ports whose types or units differ and FINROC has no conversion for it.",
    explanation: "FINROC (17.03) connects two ports when their types are equal or implicitly
castable, when the edge lists conversion operations (`<conversion>`), or when both are
numeric (a legacy static_cast, logged as a warning). Otherwise it logs `Data types
require explicit conversion` and creates no connection. Between numeric ports of
different physical quantities (a length into a velocity) FINROC converts the number and
the meaning is lost. Types and units come from the catalogue and the files'
<interface>s; edges with an unknown end are not judged.

Bad:
    <edge src=\"Simulation/Sensor Output/Pose\" dest=\"Control/Sensor Input/Ir Distance Front\"/>

Fix: connect ports of the same quantity, or add a <conversion> (version 1703).",
    fixtures: "compiler/finroc/src/checks/f111_edge_type_mismatch",
};

use super::{Context, Facts};
use crate::resolve::End;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};

fn numeric(ty: &str) -> bool {
    matches!(
        ty,
        "double"
            | "float"
            | "int8"
            | "int16"
            | "int32"
            | "int64"
            | "uint8"
            | "uint16"
            | "uint32"
            | "uint64"
            | "bool"
    ) || ty.starts_with("finroc.ib2c.")
}

pub fn check(ctx: &Context<'_>, facts: &Facts<'_>, out: &mut Diagnostics) {
    for (i, edge) in ctx.doc.edges.iter().enumerate() {
        if edge.conversion.is_some() || facts.duplicate_of.contains_key(&i) {
            continue;
        }
        let (
            End::Port {
                ty: Some(a),
                unit: ua,
                ..
            },
            End::Port {
                ty: Some(b),
                unit: ub,
                ..
            },
        ) = &facts.ends[i]
        else {
            continue;
        };
        if a != b && !(numeric(a) && numeric(b)) {
            out.push(
                Diagnostic::new(&CHECK, edge.dest.raw.span, format!("`{a}` cannot flow into `{b}`"))
                    .label(format!("a `{b}` port"))
                    .secondary(edge.src.raw.span, format!("a `{a}` port"))
                    .help("FINROC creates no connection: connect a port of the same type, or add a <conversion> (version 1703)"),
            );
            continue;
        }
        if let (Some(ua), Some(ub)) = (ua, ub) {
            let (Ok(x), Ok(y)) = (
                ferroc_values::units::parse_unit(ua),
                ferroc_values::units::parse_unit(ub),
            ) else {
                continue;
            };
            if matches!(
                ferroc_values::units::relate(&x, &y),
                ferroc_values::units::UnitRelation::DifferentDimension
            ) {
                out.push(
                    Diagnostic::new(
                        &CHECK,
                        edge.dest.raw.span,
                        format!("a quantity in {ua} goes into a port in {ub}"),
                    )
                    .label(format!("measured in {ub}"))
                    .secondary(edge.src.raw.span, format!("measured in {ua}"))
                    .help("connect ports of the same quantity"),
                );
            }
        }
    }
}
