//! Dead triggers (D115) and latent lock-order inversions (D117), the neighbours of the
//! deadlock search (`reference/deadlocks.md` §2.6): trigger cycles of data-triggered
//! modules that never start (a least "alive" fixpoint), and lock-order cycles that are
//! harmless only because a guard (a shared thread, a gate lock) serialises them.

use super::follow::follow;
use super::{DeadTrigger, Held, Latent, Model, WaitKind};
use ferroc_diagnostics::source::Span;
use ferroc_model::ir::{Application, ElementId, ElementKind, Endpoint};
use ferroc_model::library::{LibrarySet, PortDir, PortRole};
use hashbrown::HashMap;
use petgraph::graph::{DiGraph, NodeIndex};
use petgraph::Direction::Incoming;

/// Modules of data-triggered containers that are never triggered and lie on a cycle.
pub(super) fn dead_triggers(app: &Application, libs: &LibrarySet) -> Vec<DeadTrigger> {
    let data_modules: Vec<ElementId> = app
        .modules()
        .map(|(id, _)| id)
        .filter(|&id| on_data(app, id))
        .collect();
    if data_modules.is_empty() {
        return Vec::new();
    }
    let triggers = Triggers::of(app, libs, &data_modules);
    let alive = triggers.alive();
    never_triggered_cycles(&data_modules, &alive, &triggers.into)
}

/// Whether module `m` runs in a data-triggered thread container.
fn on_data(app: &Application, m: ElementId) -> bool {
    app.element(m).thread.is_some_and(|t| {
        matches!(
            app.element(t).kind,
            ElementKind::Thread {
                data_trigger: true,
                ..
            }
        )
    })
}

/// Who triggers the data-triggered modules.
struct Triggers {
    /// Modules started from outside: by initial items or by a writer of a periodic
    /// container.
    started: Vec<ElementId>,
    /// Writer → data-triggered readers.
    readers: HashMap<ElementId, Vec<ElementId>>,
    /// Reader → its incoming edges (writer, place of the connection).
    into: HashMap<ElementId, Vec<(ElementId, Span)>>,
}

impl Triggers {
    fn of(app: &Application, libs: &LibrarySet, data_modules: &[ElementId]) -> Self {
        let mut started: hashbrown::HashSet<ElementId> = Default::default();
        let mut t = Triggers {
            started: Vec::new(),
            readers: HashMap::new(),
            into: HashMap::new(),
        };
        for &m in data_modules {
            for (i, p) in app.module_ports(libs, m) {
                if p.dir != PortDir::In || p.role == PortRole::Service {
                    continue;
                }
                let input = Endpoint::Port {
                    element: m,
                    port: i,
                };
                for r in follow(app, input, Incoming) {
                    let c = &app.connections[r.first];
                    // Initial items belong to the queue, wherever on the path it is declared.
                    let initial = r
                        .queued
                        .map_or(c.initial, |hop| app.connections[hop].initial);
                    let writer = r.end.element();
                    // Initial items and writers of periodic containers start it.
                    let periodic = !on_data(app, writer) && app.element(writer).thread.is_some();
                    if (initial > 0 || periodic) && started.insert(m) {
                        t.started.push(m);
                    }
                    t.readers.entry(writer).or_default().push(m);
                    t.into.entry(m).or_default().push((writer, c.to_span));
                }
            }
        }
        t
    }

    /// The modules that are ever triggered (the least fixpoint from the started ones).
    fn alive(&self) -> hashbrown::HashSet<ElementId> {
        let mut alive: hashbrown::HashSet<ElementId> = self.started.iter().copied().collect();
        let mut work = self.started.clone();
        while let Some(w) = work.pop() {
            for &r in self.readers.get(&w).into_iter().flatten() {
                if alive.insert(r) {
                    work.push(r);
                }
            }
        }
        alive
    }
}

/// Cycles among the never-triggered modules, each walked from its smallest module.
fn never_triggered_cycles(
    data_modules: &[ElementId],
    alive: &hashbrown::HashSet<ElementId>,
    into: &HashMap<ElementId, Vec<(ElementId, Span)>>,
) -> Vec<DeadTrigger> {
    let mut g: DiGraph<ElementId, Span> = DiGraph::new();
    let mut idx: HashMap<ElementId, NodeIndex> = HashMap::new();
    for &m in data_modules.iter().filter(|m| !alive.contains(*m)) {
        idx.insert(m, g.add_node(m));
    }
    for (&m, edges) in into {
        for (w, span) in edges {
            if let (Some(&a), Some(&b)) = (idx.get(w), idx.get(&m)) {
                g.add_edge(a, b, *span);
            }
        }
    }
    let mut out = Vec::new();
    for scc in petgraph::algo::tarjan_scc(&g) {
        if scc.len() < 2 && !g.contains_edge(scc[0], scc[0]) {
            continue;
        }
        // Walk the cycle from the smallest module, staying inside the SCC.
        let set: hashbrown::HashSet<NodeIndex> = scc.iter().copied().collect();
        let start = *scc.iter().min_by_key(|n| g[**n]).unwrap_or(&scc[0]);
        let mut modules = Vec::new();
        let mut cur = start;
        let mut seen = hashbrown::HashSet::new();
        while seen.insert(cur) {
            let Some(e) = g
                .edges(cur)
                .filter(|e| set.contains(&petgraph::visit::EdgeRef::target(e)))
                .min_by_key(|e| g[petgraph::visit::EdgeRef::target(e)])
            else {
                break;
            };
            let next = petgraph::visit::EdgeRef::target(&e);
            modules.push((g[next], *e.weight()));
            cur = next;
        }
        modules.sort_by_key(|(m, _)| *m);
        out.push(DeadTrigger { modules });
    }
    out.sort_by_key(|d| d.modules.first().map(|m| m.0));
    out
}

/// Lock-order cycles (lock B taken while holding A, and A while holding B …) whose
/// wait-states share a guard, so the search rejected them: notes, not errors.
pub(super) fn latent_inversions(m: &Model, covered: &[bool]) -> Vec<Latent> {
    // Edges outer lock → inner lock, labelled with the wait-state taking the inner one.
    let mut edges: Vec<(u32, u32, u32)> = Vec::new();
    for (i, w) in m.waits.iter().enumerate() {
        let WaitKind::Lock { lock } = w.kind else {
            continue;
        };
        for h in &w.held {
            if let Held::Lock(outer) = *h {
                edges.push((outer, lock, i as u32));
            }
        }
    }
    if edges.is_empty() {
        return Vec::new();
    }
    let mut g: DiGraph<u32, u32> = DiGraph::new();
    let nodes: Vec<NodeIndex> = (0..m.locks.len()).map(|l| g.add_node(l as u32)).collect();
    for (a, b, w) in &edges {
        g.add_edge(nodes[*a as usize], nodes[*b as usize], *w);
    }
    let mut out = Vec::new();
    for scc in petgraph::algo::tarjan_scc(&g) {
        if scc.len() < 2 {
            continue;
        }
        // A two-lock cycle is what people recognise; take the first pair found.
        let set: hashbrown::HashSet<NodeIndex> = scc.iter().copied().collect();
        let mut found = None;
        'outer: for &a in &scc {
            for e in g.edges(a) {
                let b = petgraph::visit::EdgeRef::target(&e);
                if !set.contains(&b) {
                    continue;
                }
                if let Some(back) = g
                    .edges(b)
                    .find(|x| petgraph::visit::EdgeRef::target(x) == a)
                {
                    found = Some(vec![(*e.weight(), g[a]), (*back.weight(), g[b])]);
                    break 'outer;
                }
            }
        }
        let Some(cycle) = found else { continue };
        if cycle.iter().any(|(w, _)| covered[*w as usize]) {
            continue;
        }
        let first = &m.waits[cycle[0].0 as usize].held;
        let guard = first
            .iter()
            .copied()
            .filter(|h| {
                cycle
                    .iter()
                    .all(|(w, _)| m.waits[*w as usize].held.contains(h))
            })
            .find(|h| !cycle.iter().any(|(_, outer)| *h == Held::Lock(*outer)));
        if let Some(guard) = guard {
            out.push(Latent {
                edges: cycle,
                guard,
            });
        }
    }
    out
}
