//! Following connections from a module port to the module ports at their other ends,
//! through group ports: the deadlock model needs the real writers, readers and servers
//! and the queue a path declares, wherever on the path it is written.

use ferroc_model::ir::{Application, Endpoint};
use petgraph::visit::EdgeRef;
use petgraph::Direction::Outgoing;

/// One module port reached by [`follow`], with the connections (indices) on the way.
pub(super) struct Reach {
    pub end: Endpoint,
    /// The hop next to `start`.
    pub first: usize,
    /// The hop nearest `start` that declares `queue=`: a queue written on a connection
    /// into or out of a group port makes the whole path a queue (as the plan does).
    pub queued: Option<usize>,
}

/// Module ports reached from `start` along connections in `dir`, through group ports.
pub(super) fn follow(app: &Application, start: Endpoint, dir: petgraph::Direction) -> Vec<Reach> {
    let mut out = Vec::new();
    let Some(n) = app.node(start) else {
        return out;
    };
    let mut stack = vec![(n, usize::MAX, None)];
    let mut seen = vec![n];
    while let Some((node, first, queued)) = stack.pop() {
        for e in app.graph.edges_directed(node, dir) {
            let next = if dir == Outgoing {
                e.target()
            } else {
                e.source()
            };
            let hop = *e.weight();
            let first = if first == usize::MAX { hop } else { first };
            let queued = queued.or(app.connections[hop].queue.map(|_| hop));
            match app.graph[next] {
                Endpoint::Port { .. } => out.push(Reach {
                    end: app.graph[next],
                    first,
                    queued,
                }),
                Endpoint::GroupPort { .. } => {
                    if !seen.contains(&next) && seen.len() < 4096 {
                        seen.push(next);
                        stack.push((next, first, queued));
                    }
                }
                Endpoint::Param { .. } => {}
            }
        }
    }
    out
}
