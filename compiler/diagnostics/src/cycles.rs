//! Dependency cycles reported once per strongly connected component, as its shortest
//! cycle, each hop pointing at the place that creates it: library `<depends>` (L103)
//! and FINROC make.xml `libs` (L106) share it.

use crate::check::CheckInfo;
use crate::diagnostic::{Diagnostic, Diagnostics};
use crate::source::Span;
use petgraph::graph::{DiGraph, NodeIndex};
use std::collections::VecDeque;

/// One edge of a [`DependencyGraph`]: the node depended on and the place that says so.
#[derive(Clone, Copy, Debug)]
pub struct Dependency {
    pub to: usize,
    /// Where the dependency is written (a `<depends>` value, one name in a `libs` list).
    pub span: Span,
    /// How the hop reads in a label: "depends on", "optionally depends on".
    pub verb: &'static str,
}

/// What [`report_dependency_cycles`] needs to know about a graph: nodes `0..node_count()`, each
/// with a name and its dependencies in the order they are written.
pub trait DependencyGraph {
    fn node_count(&self) -> usize;
    fn name(&self, node: usize) -> &str;
    fn dependencies(&self, node: usize) -> Vec<Dependency>;
}

/// How one check words its cycle findings.
pub struct CycleReport {
    pub check: &'static CheckInfo,
    /// Start of the message, before the names: "library dependency cycle".
    pub what: &'static str,
    pub help: &'static str,
}

/// Reports each strongly connected component of `graph` once (in `report.check`'s name), as
/// its shortest cycle through the component's first node, each hop pointing at the place
/// that creates it. A node that depends on itself is a cycle of one hop.
pub fn report_dependency_cycles(
    graph: &impl DependencyGraph,
    report: &CycleReport,
    out: &mut Diagnostics,
) {
    let edges: Vec<Vec<Dependency>> = (0..graph.node_count())
        .map(|n| graph.dependencies(n))
        .collect();
    let mut g: DiGraph<usize, usize> = DiGraph::with_capacity(edges.len(), 0);
    let nodes: Vec<NodeIndex> = (0..edges.len()).map(|n| g.add_node(n)).collect();
    for (n, deps) in edges.iter().enumerate() {
        for (k, dep) in deps.iter().enumerate() {
            g.add_edge(nodes[n], nodes[dep.to], k);
        }
    }
    let mut component_of = vec![usize::MAX; edges.len()];
    for (c, component) in petgraph::algo::kosaraju_scc(&g).into_iter().enumerate() {
        for n in &component {
            component_of[g[*n]] = c;
        }
        let start = *component.iter().min().expect("components are not empty");
        if component.len() < 2 && g.find_edge(start, start).is_none() {
            continue;
        }
        let Some(hops) = shortest_cycle(&g, start, &component_of) else {
            continue;
        };
        let names: Vec<&str> = hops
            .iter()
            .map(|(n, _)| graph.name(*n))
            .chain([graph.name(hops[0].0)])
            .collect();
        let hop = |i: usize| {
            let (n, k) = hops[i];
            let dep = edges[n][k];
            (
                dep.span,
                format!("`{}` {} `{}`", names[i], dep.verb, names[i + 1]),
            )
        };
        let (span, label) = hop(0);
        let mut d = Diagnostic::new(
            report.check,
            span,
            format!("{}: {}", report.what, names.join(" → ")),
        )
        .label(label);
        for i in 1..hops.len() {
            let (span, label) = hop(i);
            d = d.secondary(span, label);
        }
        out.push(d.help(report.help));
    }
}

/// BFS from `start` back to itself inside its component: the hops as (node, edge index).
fn shortest_cycle(
    graph: &DiGraph<usize, usize>,
    start: NodeIndex,
    component_of: &[usize],
) -> Option<Vec<(usize, usize)>> {
    let component = component_of[graph[start]];
    let mut prev: std::collections::HashMap<NodeIndex, (NodeIndex, usize)> = Default::default();
    let mut queue = VecDeque::from([start]);
    while let Some(n) = queue.pop_front() {
        let mut edges: Vec<_> = graph
            .edges(n)
            .map(|e| (petgraph::visit::EdgeRef::target(&e), *e.weight()))
            .collect();
        edges.sort();
        for (t, k) in edges {
            if component_of[graph[t]] != component {
                continue;
            }
            if t == start {
                let mut hops = vec![(graph[n], k)];
                let mut cur = n;
                while cur != start {
                    let (p, pk) = prev[&cur];
                    hops.push((graph[p], pk));
                    cur = p;
                }
                hops.reverse();
                return Some(hops);
            }
            if let std::collections::hash_map::Entry::Vacant(e) = prev.entry(t) {
                e.insert((n, k));
                queue.push_back(t);
            }
        }
    }
    None
}
