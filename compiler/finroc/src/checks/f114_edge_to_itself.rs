//! F114 `edge-to-itself`: an edge connects a port to itself.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "F114",
    name: "edge-to-itself",
    severity: Severity::Warning,
    summary: "An edge of a FINROC file connects a port to itself.",
    explanation: "FINROC refuses to connect a port to itself: `ConnectTo` logs \"Cannot connect
port to itself.\" and makes no connection, so the edge has no effect and the program
runs on. Such an edge is usually an editing slip — one end was meant to name another
port (often the port of the same name on the element upstream or downstream).
ferroc compares the two ends as FINROC reads them: the same scheme and the same path
after percent escapes are decoded.

Bad:
    <edge src=\"Nav/Sensor Input/Pose\" dest=\"Nav/Sensor Input/Pose\"/>

Fix: make one end name the port the data should come from or go to, or delete the
edge.",
    fixtures: "compiler/finroc/src/checks/f114_edge_to_itself",
};

use super::{key, Context};
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};

/// Reports each edge whose two ends name the same port.
pub fn check(ctx: &Context<'_>, out: &mut Diagnostics) {
    for edge in &ctx.doc.edges {
        // An end FINROC cannot decode is F101's, not a port.
        if edge.src.segments.is_empty() || key(&edge.src) != key(&edge.dest) {
            continue;
        }
        out.push(
            Diagnostic::new(
                &CHECK,
                edge.span,
                format!("this edge connects `{}` to itself", edge.src.path()),
            )
            .label("FINROC refuses it (\"Cannot connect port to itself.\"): it has no effect")
            .help("make one end name the port the data comes from or goes to, or delete the edge"),
        );
    }
}
