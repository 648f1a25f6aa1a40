//! T108 `multiple-writers`: Several connections write into one latest-value input.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};

pub static CHECK: CheckInfo = CheckInfo {
    code: "T108",
    name: "multiple-writers",
    severity: Severity::Warning,
    summary: "Several connections write into one latest-value input.",
    explanation:
        "A latest-value input keeps only the newest value; with two writers the last writer wins and
the consumer sees an arbitrary interleaving. Queues (`queue=\"N\"`) and inputs declared
`fan-in=\"merge\"` accept several writers by design.

Bad:
    <connect from=\"robot/main/joystick/speed\" to=\"robot/main/motor/speed\"/>
    <connect from=\"robot/main/planner/speed\" to=\"robot/main/motor/speed\"/>

Fix: add an arbitration module (e.g. `ferroc_std.FlexiSelect`) or make the input a queue.
(Several sources into an iB2C inhibition port are reported as B105 instead.)",
    fixtures: "compiler/checks/src/connections/t108_multiple_writers",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    use petgraph::Direction::Incoming;
    let graph = &ctx.app.graph;
    for node in graph.node_indices() {
        // Cheap test first: most inputs have one writer.
        if graph.edges_directed(node, Incoming).nth(1).is_none() {
            continue;
        }
        let Some(view) = ctx.app.view(ctx.libraries, graph[node]) else {
            continue;
        };
        if view.merge {
            continue;
        }
        // Several sources into a behaviour's inhibition port are an error of their own (B105).
        if view.role == ferroc_model::library::PortRole::Meta
            && view.name.starts_with("inhibition/")
        {
            continue;
        }
        let mut writers: Vec<_> = graph
            .edges_directed(node, Incoming)
            .map(|e| &ctx.app.connections[*e.weight()])
            .filter(|c| c.queue.is_none())
            .collect();
        if writers.len() < 2 {
            continue;
        }
        writers.sort_by_key(|c| (c.span.file, c.span.start));
        writers.dedup_by_key(|c| (c.from, c.from_index));
        if writers.len() < 2 {
            continue;
        }
        let mut d = Diagnostic::new(
            &CHECK,
            writers[1].to_span,
            format!(
                "{} connections write into the latest-value input `{}`; the last writer wins",
                writers.len(),
                view.name
            ),
        )
        .label("another writer")
        .secondary(writers[0].to_span, "first writer");
        for w in &writers[2..] {
            d = d.secondary(w.to_span, "another writer");
        }
        out.push(d.help("arbitrate with a selector module (ferroc_std.FlexiSelect), make the input a queue (queue=\"N\"), or declare fan-in=\"merge\" on the port"));
    }
}
