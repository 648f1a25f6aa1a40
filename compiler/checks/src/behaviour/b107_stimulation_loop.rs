//! B107 `stimulation-loop`: Behaviours stimulate each other in a loop (or one stimulates
//! itself).

use super::{behaviours, sources};
use crate::{CheckInfo, PassContext};
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics, Severity};
use ferroc_model::ir::{ElementId, Endpoint};
use hashbrown::{HashMap, HashSet};
use petgraph::graph::{DiGraph, EdgeIndex, NodeIndex};
use petgraph::visit::EdgeRef;
use std::collections::VecDeque;

pub static CHECK: CheckInfo = CheckInfo {
    code: "B107",
    name: "stimulation-loop",
    severity: Severity::Warning,
    summary: "Behaviours stimulate each other in a loop.",
    explanation:
        "Stimulation is how iB2C sequences and enables behaviours: `a/activity → b/stimulation`
lets `b` act only while `a` does. A chain of stimulations that leads back to where it
started (`a → b → c → a`, or `a → a`) keeps itself alive: once any member is active, all
of them can stay active although nothing outside the loop asks for it, and none can start
unless one already runs. One warning names the whole loop, shortest path first; each hop
points at the connection (followed through group ports) that makes it. Inhibition is not
stimulation: two competitors inhibiting each other is the normal iB2C pattern and no loop.

Bad:
    <connect from=\"explore/activity\" to=\"follow_wall/stimulation\"/>
    <connect from=\"follow_wall/activity\" to=\"explore/stimulation\"/>

Fix: stimulate the members from outside the loop (a coordinating behaviour, a
`ferroc_std.ConstantActivity`, or `stimulation_mode` `enabled`) and remove one stimulation
of the loop; end a sequence with inhibition rather than a stimulation back to its start.",
    fixtures: "compiler/checks/src/behaviour/b107_stimulation_loop",
};

/// One stimulation: the connection that shows it (the hop declared in the outermost
/// scope) and whether it passes group ports.
type Hop = (usize, bool);

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    let mut graph: DiGraph<ElementId, Hop> = DiGraph::new();
    let mut nodes: HashMap<ElementId, NodeIndex> = HashMap::new();
    let mut inputs = Vec::new();
    for (id, _, mt) in behaviours(ctx) {
        nodes.insert(id, graph.add_node(id));
        if let Some(&port) = mt.port_index.get("stimulation") {
            inputs.push((id, port as u32));
        }
    }
    for (id, port) in inputs {
        let input = Endpoint::Port { element: id, port };
        for s in sources(ctx.app, ctx.libraries, input) {
            if let (Some(&a), Some(&b)) = (nodes.get(&s.module), nodes.get(&id)) {
                graph.add_edge(a, b, (s.outermost_hop(ctx.app), s.route.len() > 1));
            }
        }
    }
    for scc in petgraph::algo::tarjan_scc(&graph) {
        let single = scc.len() == 1 && !graph.contains_edge(scc[0], scc[0]);
        if single {
            continue;
        }
        // Start at the member that comes first in the model: the loop then reads in model
        // order and the hop back to it (usually written last) carries the finding.
        let Some(&start) = scc.iter().min_by_key(|n| graph[**n]) else {
            continue;
        };
        let members: HashSet<NodeIndex> = scc.iter().copied().collect();
        if let Some(cycle) = shortest_cycle(&graph, start, &members) {
            out.push(report(ctx, &graph, &cycle));
        }
    }
}

/// The shortest cycle through `start` inside one strongly connected component (BFS), as
/// edges in loop order.
fn shortest_cycle(
    graph: &DiGraph<ElementId, Hop>,
    start: NodeIndex,
    members: &HashSet<NodeIndex>,
) -> Option<Vec<EdgeIndex>> {
    let mut parent: HashMap<NodeIndex, EdgeIndex> = HashMap::new();
    let mut queue = VecDeque::from([start]);
    while let Some(u) = queue.pop_front() {
        let mut edges: Vec<_> = graph.edges(u).collect();
        edges.sort_by_key(|e| (graph[e.target()], *e.weight()));
        for e in edges {
            let v = e.target();
            if v == start {
                let mut cycle = vec![e.id()];
                let mut cur = u;
                while cur != start {
                    let back = *parent.get(&cur)?;
                    cycle.push(back);
                    cur = graph.edge_endpoints(back)?.0;
                }
                cycle.reverse();
                return Some(cycle);
            }
            if members.contains(&v) && v != start && !parent.contains_key(&v) {
                parent.insert(v, e.id());
                queue.push_back(v);
            }
        }
    }
    None
}

fn report(
    ctx: &PassContext<'_>,
    graph: &DiGraph<ElementId, Hop>,
    cycle: &[EdgeIndex],
) -> Diagnostic {
    let name = |n: NodeIndex| ctx.app.path(graph[n]);
    let short = |n: NodeIndex| ctx.app.element(graph[n]).name.as_str();
    let mut names = Vec::new();
    let mut hops = Vec::new();
    for &e in cycle {
        let Some((a, b)) = graph.edge_endpoints(e) else {
            continue;
        };
        if names.is_empty() {
            names.push(format!("`{}`", name(a)));
        }
        names.push(format!("`{}`", name(b)));
        let (shown, routed) = graph[e];
        let through = if routed { " (through group ports)" } else { "" };
        hops.push((
            ctx.app.connections[shown].to_span,
            format!("`{}` stimulates `{}`{through}", short(a), short(b)),
        ));
    }
    let closing = hops.pop();
    let (span, label) = closing.unwrap_or((ctx.app.span, String::new()));
    let message = if cycle.len() == 1 {
        format!(
            "behaviour {} stimulates itself",
            names.first().map_or("", String::as_str)
        )
    } else {
        format!("stimulation loop: {}", names.join(" → "))
    };
    let mut d = Diagnostic::new(&CHECK, span, message).label(format!("{label}, closing the loop"));
    for (span, label) in hops {
        d = d.secondary(span, label);
    }
    d.help(
        "stimulate the loop's members from outside it (a coordinating behaviour, a \
         ferroc_std.ConstantActivity, or stimulation_mode `enabled`) and remove one of these \
         stimulations; if the loop is intended, put <allow code=\"B107\" reason=\"…\"/> \
         inside the <connect> that closes it",
    )
}
