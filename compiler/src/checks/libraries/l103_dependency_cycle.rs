//! L103 `dependency-cycle`: Libraries depend on each other in a cycle.

use crate::checks::CheckInfo;
use crate::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "L103",
    name: "dependency-cycle",
    severity: Severity::Error,
    summary: "Libraries depend on each other in a cycle.",
    explanation: "Library dependencies go one way (FINROC's rule): a cycle makes build order and
initialisation order undefined. The cycle is reported once per strongly connected
component, as its shortest cycle, each hop pointing at the `<depends>` that creates it.

Bad:
    a.lib.xml: <depends library=\"b\"/>
    b.lib.xml: <depends library=\"a\"/>

Fix: move what both need into a third library both depend on.",
    pass: None,
    fixtures: "libraries/l103_dependency_cycle",
};

use crate::diagnostic::{Diagnostic, Diagnostics};
use crate::library::{LibraryId, LibrarySet};
use petgraph::graph::{DiGraph, NodeIndex};
use std::collections::VecDeque;

/// Reports each strongly connected component of the dependency graph once, as its
/// shortest cycle, every hop pointing at the `<depends>` that creates it.
pub fn report_cycles(set: &LibrarySet, out: &mut Diagnostics) {
    let mut graph: DiGraph<LibraryId, usize> = DiGraph::new();
    let nodes: Vec<NodeIndex> = (0..set.libraries.len())
        .map(|i| graph.add_node(LibraryId(i as u32)))
        .collect();
    for (i, lib) in set.libraries.iter().enumerate() {
        for (k, dep) in lib.depends.iter().enumerate() {
            if let Some(t) = dep.target {
                graph.add_edge(nodes[i], nodes[t.0 as usize], k);
            }
        }
    }
    for component in petgraph::algo::tarjan_scc(&graph) {
        let start = *component.iter().min().expect("components are not empty");
        let self_loop = graph.find_edge(start, start).is_some();
        if component.len() < 2 && !self_loop {
            continue;
        }
        let Some(cycle) = shortest_cycle(&graph, start, &component) else {
            continue;
        };
        let hops: Vec<(LibraryId, usize)> = cycle;
        let names: Vec<&str> = hops
            .iter()
            .map(|(l, _)| set.get(*l).name.as_str())
            .chain([set.get(hops[0].0).name.as_str()])
            .collect();
        let (first_lib, first_dep) = hops[0];
        let dep_span = |l: LibraryId, k: usize| set.get(l).depends[k].span;
        let mut d = Diagnostic::new(
            &CHECK,
            dep_span(first_lib, first_dep),
            format!("library dependency cycle: {}", names.join(" → ")),
        )
        .label(format!("`{}` depends on `{}`", names[0], names[1]));
        for (i, (l, k)) in hops.iter().enumerate().skip(1) {
            d = d.secondary(
                dep_span(*l, *k),
                format!("`{}` depends on `{}`", names[i], names[i + 1]),
            );
        }
        out.push(d.help("dependencies must go one way: move what these libraries share into a library that depends on none of them"));
    }
}

/// BFS from `start` back to itself inside the component: the hops as (library, depends index).
fn shortest_cycle(
    graph: &DiGraph<LibraryId, usize>,
    start: NodeIndex,
    component: &[NodeIndex],
) -> Option<Vec<(LibraryId, usize)>> {
    let mut prev: std::collections::HashMap<NodeIndex, (NodeIndex, usize)> = Default::default();
    let mut queue = VecDeque::from([start]);
    while let Some(n) = queue.pop_front() {
        let mut edges: Vec<_> = graph
            .edges(n)
            .map(|e| (petgraph::visit::EdgeRef::target(&e), *e.weight()))
            .collect();
        edges.sort();
        for (t, k) in edges {
            if !component.contains(&t) {
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
