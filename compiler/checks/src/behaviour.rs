//! Checks of area iB2C behaviour networks (B): the static rules of `checks.md` "iB2C rules
//! (B)", from the iB2C architecture and FINROC's ib2c plugin (`reference/finroc.md` §4).
//!
//! What the checks share lives here: the real sources of a module input (module outputs,
//! found backwards through group ports, the way `schedule/flow.rs` flattens them forwards),
//! the meta ports of behaviour instances, stimulation modes and iB2C groups.

pub use ferroc_model::checks::b101_meta_constant_out_of_range;
pub mod b102_meta_input_from_number;
pub mod b103_never_stimulated;
pub mod b104_stimulation_ignored;
pub mod b105_inhibition_sources;
pub mod b106_self_inhibition;
pub mod b107_stimulation_loop;
pub mod b108_incomplete_fusion_channel;
pub mod b109_mixed_fusion_channel;
pub mod b110_characteristic_behaviours;

use crate::PassContext;
use ferroc_diagnostics::source::Span;
use ferroc_model::ir::{Application, Connection, ElementId, Endpoint, ModuleInstance, ParamSource};
use ferroc_model::library::module_type::ModuleKind;
use ferroc_model::library::{LibrarySet, ModuleType, PortDir, PortRole};
use hashbrown::{HashMap, HashSet};
use petgraph::graph::NodeIndex;

/// A module output that reaches a module input, directly or through group ports.
#[derive(Clone, Debug)]
pub struct Source {
    /// The module output (an [`Endpoint::Port`]).
    pub port: Endpoint,
    pub module: ElementId,
    /// The connection leaving the output (first hop) and the one reaching the input (last
    /// hop), as indices into `Application::connections`; the same for a direct connection.
    pub first: usize,
    pub last: usize,
    /// Every hop, first to last (one route when there are several).
    pub route: Vec<usize>,
}

impl Source {
    pub fn first<'a>(&self, app: &'a Application) -> &'a Connection {
        &app.connections[self.first]
    }

    pub fn last<'a>(&self, app: &'a Application) -> &'a Connection {
        &app.connections[self.last]
    }

    /// The hop declared in the outermost scope: where a route through group ports is
    /// closed (for example a group's output wired back into its own input).
    pub fn outermost_hop(&self, app: &Application) -> usize {
        let depth = |c: usize| {
            let mut d = 0usize;
            let mut cur = app.element(app.connections[c].scope).parent;
            while let Some(p) = cur {
                d += 1;
                cur = app.element(p).parent;
            }
            d
        };
        self.route
            .iter()
            .copied()
            .min_by_key(|&c| depth(c))
            .unwrap_or(self.last)
    }
}

/// The module outputs that feed `input`, following group ports backwards; in source order
/// of their first hop, each output once. Wrongly directed connections (T101) and calls are
/// not sources.
pub fn sources(app: &Application, libs: &LibrarySet, input: Endpoint) -> Vec<Source> {
    let mut out: Vec<Source> = Vec::new();
    let Some(start) = app.node(input) else {
        return out;
    };
    // For each group port reached: the connection leaving it towards the input, and the
    // node that connection enters (a search tree rooted at the input).
    let mut next: HashMap<NodeIndex, (usize, NodeIndex)> = HashMap::new();
    let mut stack = vec![start];
    while let Some(node) = stack.pop() {
        for edge in app
            .graph
            .edges_directed(node, petgraph::Direction::Incoming)
        {
            let index = *edge.weight();
            let from = petgraph::visit::EdgeRef::source(&edge);
            match app.graph[from] {
                ep @ Endpoint::Port { element, .. } => {
                    let Some(view) = app.view(libs, ep) else {
                        continue;
                    };
                    if view.dir != PortDir::Out || view.role == PortRole::Client {
                        continue;
                    }
                    let mut route = vec![index];
                    let mut cur = node;
                    while let Some(&(c, to)) = next.get(&cur) {
                        route.push(c);
                        cur = to;
                    }
                    out.push(Source {
                        port: ep,
                        module: element,
                        first: index,
                        last: route.last().copied().unwrap_or(index),
                        route,
                    });
                }
                Endpoint::GroupPort { .. } => {
                    if from != start && !next.contains_key(&from) {
                        next.insert(from, (index, node));
                        stack.push(from);
                    }
                }
                Endpoint::Param { .. } => {}
            }
        }
    }
    out.sort_by_key(|s| {
        let c = &app.connections[s.first];
        (c.from_span.file, c.from_span.start, s.last)
    });
    let mut seen = HashSet::new();
    out.retain(|s| seen.insert((s.port, app.connections[s.first].from_index)));
    out
}

/// The behaviour (and fusion) instances of the application, with their types.
pub fn behaviours<'a>(
    ctx: &'a PassContext<'a>,
) -> impl Iterator<Item = (ElementId, &'a ModuleInstance, &'a ModuleType)> + 'a {
    ctx.app.modules().filter_map(|(id, m)| {
        let mt = ctx.app.module_type(ctx.libraries, id)?;
        mt.is_behaviour().then_some((id, m, mt))
    })
}

/// The meta input ports of a behaviour instance: (endpoint, port name).
pub fn meta_inputs<'a>(
    ctx: &'a PassContext<'a>,
    id: ElementId,
) -> impl Iterator<Item = (Endpoint, &'a str)> + 'a {
    ctx.app
        .module_ports(ctx.libraries, id)
        .filter(|(_, p)| p.role == PortRole::Meta && p.dir == PortDir::In)
        .map(move |(i, p)| {
            (
                Endpoint::Port {
                    element: id,
                    port: i,
                },
                p.name.as_str(),
            )
        })
}

/// Whether a meta input's name is an inhibition port (`inhibition/k`).
pub fn is_inhibition(name: &str) -> bool {
    name.starts_with("inhibition/")
}

/// A behaviour's stimulation mode (docs/model-language.md §4, FINROC's `Stimulation Mode`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    Auto,
    Enabled,
    Disabled,
}

/// The stimulation mode, with the span of its value when given (not for the default);
/// `None` when it is only known at start-up (`cmdline`) or not a valid choice (P103).
pub fn stimulation_mode(m: &ModuleInstance) -> Option<(Mode, Option<Span>)> {
    let Some(p) = m.params.iter().find(|p| p.name == "stimulation_mode") else {
        return Some((Mode::Auto, None));
    };
    let text = match &p.source {
        ParamSource::Inline => p.text.trim(),
        ParamSource::Config(Ok((text, _))) => text.trim(),
        ParamSource::Config(Err(_)) | ParamSource::Cmdline => return None,
    };
    let mode = match text {
        "auto" => Mode::Auto,
        "enabled" => Mode::Enabled,
        "disabled" => Mode::Disabled,
        _ => return None,
    };
    Some((mode, Some(p.span)))
}

/// The span of an instance parameter's value, if the instance sets it.
pub fn param_span(m: &ModuleInstance, name: &str) -> Option<Span> {
    m.params.iter().find(|p| p.name == name).map(|p| p.span)
}

/// iB2C groups: each group with its characteristic behaviours, in model order.
pub fn characteristic_groups(app: &Application) -> HashMap<ElementId, Vec<ElementId>> {
    let mut groups: HashMap<ElementId, Vec<ElementId>> = HashMap::new();
    for (id, m) in app.modules() {
        if m.characteristic().is_some() {
            if let Some(g) = app.enclosing_group(id) {
                groups.entry(g).or_default().push(id);
            }
        }
    }
    groups
}

/// The behaviour a source stands for, as seen by `consumer`: the module itself, or the
/// outermost iB2C group around it that does not also hold the consumer (an iB2C group's
/// activity, target rating and data outputs belong to the group as one behaviour).
pub fn behaviour_unit(
    app: &Application,
    ib2c_groups: &HashMap<ElementId, Vec<ElementId>>,
    module: ElementId,
    consumer: ElementId,
) -> ElementId {
    let mut unit = module;
    let mut cur = app.element(module).parent;
    while let Some(c) = cur {
        if app.contains(c, consumer) {
            break;
        }
        if ib2c_groups.contains_key(&c) {
            unit = c;
        }
        cur = app.element(c).parent;
    }
    unit
}

/// `robot/main/avoid/activity`: a module port by its full path.
pub fn port_path(ctx: &PassContext<'_>, port: Endpoint) -> String {
    let name = ctx.app.view(ctx.libraries, port).map_or("?", |v| v.name);
    format!("{}/{name}", ctx.app.path(port.element()))
}

/// One channel of a fusion instance: its ports in the order activity, target rating, then
/// the data ports of `<channel-in>`, each with its name inside the channel.
pub struct Channel<'a> {
    pub k: u32,
    pub ports: Vec<(Endpoint, &'a str)>,
}

/// The channels of a fusion instance (`in/k/…` ports the resolver made from `channels`).
pub fn channels<'a>(ctx: &'a PassContext<'a>, id: ElementId, mt: &ModuleType) -> Vec<Channel<'a>> {
    let mut out: Vec<Channel<'a>> = Vec::new();
    if mt.kind != ModuleKind::Fusion {
        return out;
    }
    for (i, p) in ctx.app.module_ports(ctx.libraries, id) {
        if (i as usize) < mt.ports.len() {
            continue; // the type's own ports; channels are the instance's
        }
        let Some((k, name)) = p
            .name
            .strip_prefix("in/")
            .and_then(|rest| rest.split_once('/'))
            .and_then(|(k, name)| Some((k.parse::<u32>().ok()?, name)))
        else {
            continue;
        };
        let ep = Endpoint::Port {
            element: id,
            port: i,
        };
        match out.last_mut() {
            Some(c) if c.k == k => c.ports.push((ep, name)),
            _ => out.push(Channel {
                k,
                ports: vec![(ep, name)],
            }),
        }
    }
    out
}

/// `a`, `a` and `b`, `a`, `b` and `c` — with backticks.
pub fn list(names: &[&str]) -> String {
    let quoted: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
    match quoted.split_last() {
        None => String::new(),
        Some((last, [])) => last.clone(),
        Some((last, rest)) => format!("{} and {last}", rest.join(", ")),
    }
}
