//! Connections between parts: which of the plan's connections cross from one part to
//! another, with the value type they carry and how often they send (`sharing=`).
//! The runtime turns each into a link ([`ferroc_runtime::link`] in the runtime crate);
//! a bundle writes both of its ends, one in each part's program.

use ferroc_model::ir::{Application, ElementId};
use ferroc_model::library::LibrarySet;
use ferroc_schedule::DataEdge;
use ferroc_values::types::Type;

/// A connection that crosses from one part to another.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedLink {
    /// Its number: the order of the plan's links, the same in every part's program.
    pub id: u32,
    pub from_part: String,
    pub to_part: String,
    /// The reader's model type (what travels, after any conversion).
    pub ty: String,
    /// For a library type: its library and Rust path (a bundle registers it).
    pub library: Option<String>,
    pub rust: Option<String>,
    pub sharing: LinkSharing,
    /// No value may be dropped on the way: `reliability="reliable"`, or (without
    /// `reliability=`) the reader queues with `on-full="block"`. Latest-value links
    /// (no queue) and `reliability="best-effort"` may drop values when congested.
    pub reliable: bool,
    /// `deadline=` in seconds: the longest silence the reader accepts; a longer gap
    /// between values is reported and the reader's input is stale meanwhile.
    pub deadline: Option<f64>,
}

/// `sharing=` with its time, in seconds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LinkSharing {
    /// Every new value, at most one per `min-interval` (0: no limit).
    OnChange { min_interval: f64 },
    /// The latest value every `period`.
    Periodic { period: f64 },
}

/// A client → service call that crosses from one part to another.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedCallLink {
    /// Its number: the order of the plan's calls between parts.
    pub id: u32,
    pub client_part: String,
    pub server_part: String,
    /// The request type (the client port's) and the response type (`response=`).
    pub request: Type,
    pub response: Option<Type>,
}

/// The call link of a call from `edge.from_module` to `edge.to_module`, if they are in
/// different parts.
pub(super) fn call_link_of(
    app: &Application,
    edge: &DataEdge,
    request: &Type,
    response: Option<Type>,
    id: u32,
) -> Option<PlannedCallLink> {
    let part_of = |m: ElementId| app.element(m).part;
    let (from, to) = (part_of(edge.from_module)?, part_of(edge.to_module)?);
    (from != to).then(|| PlannedCallLink {
        id,
        client_part: app.element(from).name.clone(),
        server_part: app.element(to).name.clone(),
        request: request.clone(),
        response,
    })
}

/// The link of a connection from `from_module` to `to_module` through `edge`'s hops,
/// if the two modules are in different parts; `id` is the number it gets.
pub(super) fn link_of(
    app: &Application,
    libs: &LibrarySet,
    edge: &DataEdge,
    to_type: &Type,
    id: u32,
) -> Option<PlannedLink> {
    let part_of = |m: ElementId| app.element(m).part;
    let (from, to) = (part_of(edge.from_module)?, part_of(edge.to_module)?);
    if from == to {
        return None;
    }
    let sharing = sharing_of(app, &edge.hops);
    let (library, rust) = match to_type {
        Type::Named(named, _) => {
            let named = libs.named_type(*named);
            (
                Some(libs.get(named.library).name.clone()),
                Some(named.rust.clone()),
            )
        }
        _ => (None, None),
    };
    Some(PlannedLink {
        id,
        from_part: app.element(from).name.clone(),
        to_part: app.element(to).name.clone(),
        ty: to_type.to_string(),
        library,
        rust,
        sharing,
        reliable: reliable_of(app, &edge.hops),
        deadline: (edge.hops.iter()).find_map(|&h| app.connections[h].deadline_seconds()),
    })
}

/// Whether the link made of `hops` must not drop values (see [`PlannedLink::reliable`]):
/// the first hop with `reliability=` decides, else a hop queueing with
/// `on-full="block"` (the default of a queue).
pub(super) fn reliable_of(app: &Application, hops: &[usize]) -> bool {
    let connections = hops.iter().map(|&h| &app.connections[h]);
    if let Some(reliable) = connections.clone().find_map(|c| c.reliable()) {
        return reliable;
    }
    connections
        .into_iter()
        .any(|c| c.queue.is_some() && c.on_full.as_deref().is_none_or(|f| f == "block"))
}

/// The sharing of a connection made of `hops`: the first hop that says how (normally
/// the one between the parts) decides; on-change without limit by default.
pub(super) fn sharing_of(app: &Application, hops: &[usize]) -> LinkSharing {
    for &hop in hops {
        let c = &app.connections[hop];
        match c.sharing().map(|(s, _)| s.as_str()) {
            Some("periodic") => {
                return LinkSharing::Periodic {
                    period: c.period_seconds().unwrap_or(0.0),
                }
            }
            Some(_) => {
                return LinkSharing::OnChange {
                    min_interval: c.min_interval_seconds().unwrap_or(0.0),
                }
            }
            None if c.min_interval_seconds().is_some() => {
                return LinkSharing::OnChange {
                    min_interval: c.min_interval_seconds().unwrap_or(0.0),
                }
            }
            None => {}
        }
    }
    LinkSharing::OnChange { min_interval: 0.0 }
}

/// The link of a parameter link (connection `hop`) from `source` to `target`, if they
/// are in different parts: the value travels as an `f64`.
pub(super) fn param_link_of(
    app: &Application,
    hop: usize,
    (source, target): (ElementId, ElementId),
    id: u32,
) -> Option<PlannedLink> {
    let (from, to) = (app.element(source).part?, app.element(target).part?);
    (from != to).then(|| PlannedLink {
        id,
        from_part: app.element(from).name.clone(),
        to_part: app.element(to).name.clone(),
        ty: "f64".into(),
        library: None,
        rust: None,
        sharing: sharing_of(app, &[hop]),
        reliable: reliable_of(app, &[hop]),
        deadline: app.connections[hop].deadline_seconds(),
    })
}
