//! F103 `duplicate-edge`: an edge connects two ports another edge already connects.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "F103",
    name: "duplicate-edge",
    severity: Severity::Warning,
    summary: "An edge repeats another one, possibly written in the reverse direction.",
    explanation: "FINROC connects two ports once: `ConnectTo` returns when the ports are already
connected. An edge written twice is a no-op, and so is an edge written backwards
(input → output) when the two ports are already connected: FINROC re-orients edges
without a direction flag by inferring the data direction. Such repeats are leftovers
of editing in finstruct and make the file say more than it does (a reader may think
two connections exist, or that data flows both ways).

Bad:
    <edge src=\"Sim/Sensor Output/Pose\" dest=\"Nav/Sensor Input/Pose\"/>
    <edge src=\"Nav/Sensor Input/Pose\" dest=\"Sim/Sensor Output/Pose\"/>

Fix: delete the repetition.",
    fixtures: "compiler/finroc/src/checks/f103_duplicate_edge",
};

use super::{Context, Facts};
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};

pub fn check(ctx: &Context<'_>, facts: &Facts<'_>, out: &mut Diagnostics) {
    let mut list: Vec<_> = facts.duplicate_of.iter().collect();
    list.sort();
    for (&i, &(j, reversed)) in list {
        let (edge, first) = (&ctx.doc.edges[i], &ctx.doc.edges[j]);
        let (message, label) = if reversed {
            (
                format!(
                    "this edge is an earlier one reversed: `{}` and `{}` are connected already",
                    edge.src.path(),
                    edge.dest.path()
                ),
                "FINROC re-orients it and finds the ports connected: it has no effect",
            )
        } else {
            (
                format!(
                    "`{}` → `{}` is connected twice",
                    edge.src.path(),
                    edge.dest.path()
                ),
                "the repetition has no effect",
            )
        };
        out.push(
            Diagnostic::new(&CHECK, edge.span, message)
                .label(label)
                .secondary(first.span, "first connected here")
                .help("delete this edge"),
        );
    }
}
