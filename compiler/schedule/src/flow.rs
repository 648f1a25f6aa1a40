//! Data dependencies between module ports, with group ports flattened away.
//!
//! Groups have no steps of their own: a connection into a group port continues along the
//! group's connections on the other side. The scheduler only cares which module port
//! feeds which module port, and whether any hop on the way was marked `delay="1"`.

use ferroc_model::ir::{Application, ElementId, Endpoint};
use ferroc_model::library::{LibrarySet, PortDir, PortRole};
use petgraph::graph::NodeIndex;
use petgraph::Direction::Outgoing;

/// One module output feeding one module input, possibly through group ports.
#[derive(Clone, Debug)]
pub struct DataEdge {
    pub from_module: ElementId,
    pub from_role: PortRole,
    pub to_module: ElementId,
    pub to_role: PortRole,
    /// The receiving port is an iB2C inhibition input.
    pub into_inhibition: bool,
    /// Some hop on the path is marked `delay="1"` (an intended feedback edge).
    pub delayed: bool,
    /// Indices into `Application::connections`, in path order (first hop first).
    pub hops: Vec<usize>,
}

/// Every module-to-module data dependency of the application.
pub fn data_edges(app: &Application, libs: &LibrarySet) -> Vec<DataEdge> {
    edges(app, libs, false)
}

/// Every client-to-service link of the application, followed through group ports the
/// same way (the runtime wires calls; they are not data flow).
pub fn call_edges(app: &Application, libs: &LibrarySet) -> Vec<DataEdge> {
    edges(app, libs, true)
}

fn edges(app: &Application, libs: &LibrarySet, calls: bool) -> Vec<DataEdge> {
    let mut edges = Vec::new();
    for start in app.graph.node_indices() {
        let Endpoint::Port { element, .. } = app.graph[start] else {
            continue;
        };
        let Some(view) = app.view(libs, app.graph[start]) else {
            continue;
        };
        if view.dir != PortDir::Out {
            continue; // a wrongly directed connection is T101's business
        }
        if (view.role == PortRole::Client) != calls {
            continue; // a call is not data flow (the deadlock analysis looks at calls)
        }
        let origin = Origin {
            module: element,
            role: view.role,
        };
        let mut hops = Vec::new();
        let mut visited_group_ports = Vec::new();
        follow(
            app,
            libs,
            start,
            &origin,
            false,
            &mut hops,
            &mut visited_group_ports,
            &mut edges,
        );
    }
    edges
}

struct Origin {
    module: ElementId,
    role: PortRole,
}

/// Depth-first along outgoing connections; group ports are passed through, module input
/// ports end a path. `visited` guards against group-port cycles in malformed models.
#[allow(clippy::too_many_arguments)]
fn follow(
    app: &Application,
    libs: &LibrarySet,
    node: NodeIndex,
    origin: &Origin,
    delayed: bool,
    hops: &mut Vec<usize>,
    visited: &mut Vec<NodeIndex>,
    out: &mut Vec<DataEdge>,
) {
    for edge in app.graph.edges_directed(node, Outgoing) {
        let index = *edge.weight();
        let connection = &app.connections[index];
        let target = petgraph::visit::EdgeRef::target(&edge);
        let delayed = delayed || connection.delay;
        hops.push(index);
        match app.graph[target] {
            Endpoint::Port { element, .. } => {
                if let Some(view) = app.view(libs, app.graph[target]) {
                    if view.dir == PortDir::In {
                        out.push(DataEdge {
                            from_module: origin.module,
                            from_role: origin.role,
                            to_module: element,
                            to_role: view.role,
                            into_inhibition: view.role == PortRole::Meta
                                && view.name.starts_with("inhibition"),
                            delayed,
                            hops: hops.clone(),
                        });
                    }
                }
            }
            Endpoint::GroupPort { .. } => {
                if !visited.contains(&target) {
                    visited.push(target);
                    follow(app, libs, target, origin, delayed, hops, visited, out);
                    visited.pop();
                }
            }
            // Parameters driven by ports change configuration, not this cycle's data.
            Endpoint::Param { .. } => {}
        }
        hops.pop();
    }
}
