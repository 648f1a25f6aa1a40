//! F102 `edge-end-missing`: an edge names a port that does not exist.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "F102",
    name: "edge-end-missing",
    severity: Severity::Error,
    summary: "An edge of a FINROC file names a port that does not exist.",
    explanation: "FINROC resolves an edge's paths when it loads the file. If neither port
exists it logs a warning and drops the edge; if one exists it creates a pending
connector (tLocalUriConnector) that connects when the other port appears, which for a
misspelt name is never. Either way the data does not flow and the program runs on.
ferroc knows the ports from the file itself (its <interface>s and elements), the group
files of the checkout and the catalogue of component types; ends it cannot know (a
type not in the catalogue) are listed as not checked.

Bad (AddNoise's ports are Input/Input and Output/Output):
    <edge src=\"AddNoise Rear/Output/Out\" dest=\"Sensor Output/Ir Distance Rear\"/>

Fix: write the port's path as FINROC names it (Element/Interface/Port).",
    fixtures: "compiler/finroc/src/checks/f102_edge_end_missing",
};

use super::{Context, Facts};
use crate::resolve::End;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};

pub fn check(ctx: &Context<'_>, facts: &Facts<'_>, out: &mut Diagnostics) {
    for (i, edge) in ctx.doc.edges.iter().enumerate() {
        let (s, d) = &facts.ends[i];
        let missing: Vec<(&crate::finstructable::EdgeEnd, &String)> =
            [(&edge.src, s), (&edge.dest, d)]
                .into_iter()
                .filter_map(|(e, r)| match r {
                    End::Missing(why) => Some((e, why)),
                    _ => None,
                })
                .collect();
        let Some((first, why)) = missing.first() else {
            continue;
        };
        let both = missing.len() == 2;
        let (label, severity) = if both {
            (
                "FINROC drops this edge (neither port exists)",
                Severity::Error,
            )
        } else {
            (
                "FINROC leaves this edge pending: it connects only if this port ever appears",
                Severity::Warning,
            )
        };
        let mut d = Diagnostic::new(
            &CHECK,
            first.raw.span,
            format!("`{}` does not exist: {why}", first.path()),
        )
        .label(label)
        .severity(severity)
        .help("write the port's path as FINROC names it: Element/Interface/Port");
        if let Some((second, why2)) = missing.get(1) {
            d = d.secondary(
                second.raw.span,
                format!("`{}` does not exist either: {why2}", second.path()),
            );
        }
        out.push(d);
    }
}
