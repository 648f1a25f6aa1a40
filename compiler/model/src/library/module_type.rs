//! Module types as declared in manifests: ports, parameters, flexible port groups and the
//! ports and parameters each kind implies (iB2C meta ports, fusion channels).

use super::{unit_attr, LibraryId, LibrarySet};
use crate::checks::{m105_misplaced_element, m109_duplicate_name};
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};
use ferroc_diagnostics::source::Span;
use ferroc_syntax::Element;
use ferroc_values::types::Type;
use ferroc_values::units::Unit;
use hashbrown::HashMap;

mod behaviour;
mod params;

pub use params::check_value;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModuleKind {
    Module,
    SenseControl,
    Behaviour,
    Fusion,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PortDir {
    In,
    Out,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PortRole {
    Plain,
    Sensor,
    Controller,
    /// iB2C meta port generated from the kind (stimulation, activity, …).
    Meta,
    /// `<client>`: calls a service (an output: requests leave here).
    Client,
    /// `<service>`: served by this module (an input: requests arrive here).
    Service,
}

/// A port's type: fixed, or the type of an instance-declared flexible port group (`$in`).
#[derive(Clone, Debug, PartialEq)]
pub enum PortType {
    Fixed(Type),
    SameAs(String),
}

#[derive(Clone, Debug)]
pub struct PortDecl {
    pub name: String,
    pub dir: PortDir,
    pub role: PortRole,
    pub ty: PortType,
    pub unit: Option<Unit>,
    pub required: bool,
    pub blocking_read: bool,
    /// `timeout` of a blocking read (`None`: waits forever).
    pub read_timeout: super::steps::Timeout,
    pub merge: bool,
    pub span: Span,
}

#[derive(Clone, Debug)]
pub struct ParamDecl {
    pub name: String,
    pub ty: Type,
    pub unit: Option<Unit>,
    pub min: Option<f64>,
    pub max: Option<f64>,
    pub default: Option<String>,
    pub required: bool,
    pub choices: Vec<String>,
    /// The value at which the module reads the wall clock or the OS's randomness (a
    /// seed where 0 means "from the clock"): `nondeterministic-value="0"`, or a `doc`
    /// that says so. With the span that says it (X106 points there).
    pub nondeterministic_value: Option<(String, Span)>,
    pub span: Span,
}

/// `<flexible port dir same-type min-count max-count>`: instances declare this port group.
#[derive(Clone, Debug)]
pub struct FlexibleDecl {
    pub port: String,
    pub dir: PortDir,
    pub same_type: bool,
    pub min_count: u32,
    pub max_count: Option<u32>,
    pub span: Span,
}

#[derive(Clone, Debug)]
pub struct ModuleType {
    pub name: String,
    pub qualified: String,
    pub library: LibraryId,
    pub kind: ModuleKind,
    pub rust: String,
    pub ports: Vec<PortDecl>,
    pub port_index: HashMap<String, usize>,
    pub params: Vec<ParamDecl>,
    pub param_index: HashMap<String, usize>,
    pub flexible: Vec<FlexibleDecl>,
    /// Fusion: the data ports of one channel.
    pub channel_in: Vec<PortDecl>,
    /// Behaviour: declared derived activities.
    pub derived_activities: Vec<String>,
    pub clients: Vec<super::steps::ClientDecl>,
    pub services: Vec<super::steps::ServiceDecl>,
    /// Lock slots (`<locks order>`, then slots named only by steps), with their spans.
    pub lock_slots: Vec<(String, Span)>,
    /// Each `<locks order="a b">`: slots in the order they are nested.
    pub lock_orders: Vec<Vec<String>>,
    /// What each activity does that can wait; one default `update` if none is declared.
    pub activities: Vec<super::steps::ActivityDecl>,
    /// `budget="2ms"`: worst-case execution time of one activation, seconds (value span).
    pub budget: Option<(f64, Span)>,
    /// `nondeterministic="true"`: the type reads the wall clock or the OS's
    /// randomness, so a lockstep run differs from the next (X106); the value's span.
    pub nondeterministic: Option<Span>,
    pub span: Span,
}

impl ModuleType {
    pub fn param(&self, name: &str) -> Option<&ParamDecl> {
        self.param_index.get(name).map(|i| &self.params[*i])
    }

    pub fn port(&self, name: &str) -> Option<&PortDecl> {
        self.port_index.get(name).map(|i| &self.ports[*i])
    }

    pub fn is_behaviour(&self) -> bool {
        matches!(self.kind, ModuleKind::Behaviour | ModuleKind::Fusion)
    }
}

pub fn build_all(set: &LibrarySet, id: LibraryId, diags: &mut Diagnostics) -> Vec<ModuleType> {
    let lib = set.get(id);
    let mut out: Vec<ModuleType> = Vec::new();
    for element in lib.root.children_named("module-type") {
        let Some(name) = element.value("name") else {
            continue;
        };
        if let Some(first) = out.iter().find(|m| m.name == name) {
            diags.push(
                Diagnostic::new(
                    &m109_duplicate_name::CHECK,
                    element.value_span("name"),
                    format!("module type `{name}` is defined twice"),
                )
                .label("second definition")
                .secondary(first.span, "first definition")
                .help("rename or remove one of them"),
            );
            continue;
        }
        out.push(build(set, id, element, diags));
    }
    out
}

fn build(
    set: &LibrarySet,
    id: LibraryId,
    element: &Element,
    diags: &mut Diagnostics,
) -> ModuleType {
    let lib = set.get(id);
    let mut mt = declared_type(&lib.name, id, element, diags);
    // Ports share one namespace across directions; parameters (addressed as `param/x`) another.
    let mut names: HashMap<String, Span> = HashMap::new();
    let mut param_names: HashMap<String, Span> = HashMap::new();
    for child in &element.children {
        match child.name.as_str() {
            "param" => {
                if let Some(p) = params::param_decl(set, &lib.visible, child, diags) {
                    if unique(&mut param_names, &p.name, p.span, diags) {
                        mt.params.push(p);
                    }
                }
            }
            "flexible" => mt.flexible.extend(flexible_decl(child)),
            "derived-activity" => {
                if !mt.is_behaviour() {
                    misplaced(
                        child,
                        "only behaviour and fusion module types have derived activities",
                        diags,
                    );
                } else if let Some(n) = child.value("name") {
                    mt.derived_activities.push(n.to_string());
                }
            }
            "channel-in" => {
                if mt.kind != ModuleKind::Fusion {
                    misplaced(child, "only fusion module types have channels", diags);
                } else if let Some(p) = port_decl(
                    set,
                    &lib.visible,
                    child,
                    PortDir::In,
                    PortRole::Plain,
                    diags,
                ) {
                    mt.channel_in.push(p);
                }
            }
            _ => {
                if let Some(p) = data_port(set, &lib.visible, child, mt.kind, diags) {
                    if unique(&mut names, &p.name, p.span, diags) {
                        mt.ports.push(p);
                    }
                }
            }
        }
    }
    super::steps::add_rpc_ports(set, &lib.visible, element, &mut mt, &mut names, diags);
    if mt.is_behaviour() {
        behaviour::add_behaviour_interface(&mut mt);
    }
    mt.port_index = mt
        .ports
        .iter()
        .enumerate()
        .map(|(i, p)| (p.name.clone(), i))
        .collect();
    mt.param_index = mt
        .params
        .iter()
        .enumerate()
        .map(|(i, p)| (p.name.clone(), i))
        .collect();
    super::steps::build(element, &mut mt, diags);
    mt
}

/// The module type as its `<module-type>` attributes declare it, with no ports,
/// parameters or activities yet.
fn declared_type(
    library: &str,
    id: LibraryId,
    element: &Element,
    diags: &mut Diagnostics,
) -> ModuleType {
    let name = element.value("name").unwrap_or("").to_string();
    let kind = match element.value("kind") {
        Some("sense-control") => ModuleKind::SenseControl,
        Some("behaviour") => ModuleKind::Behaviour,
        Some("fusion") => ModuleKind::Fusion,
        _ => ModuleKind::Module,
    };
    ModuleType {
        qualified: format!("{library}.{name}"),
        name,
        library: id,
        kind,
        rust: element.value("rust").unwrap_or("").to_string(),
        ports: Vec::new(),
        port_index: HashMap::new(),
        params: Vec::new(),
        param_index: HashMap::new(),
        flexible: Vec::new(),
        channel_in: Vec::new(),
        derived_activities: Vec::new(),
        clients: Vec::new(),
        services: Vec::new(),
        lock_slots: Vec::new(),
        lock_orders: Vec::new(),
        activities: Vec::new(),
        budget: super::steps::duration_attr(element, "budget", diags),
        nondeterministic: (element.value("nondeterministic") == Some("true"))
            .then(|| element.value_span("nondeterministic")),
        span: element.value_span("name"),
    }
}

/// A `<flexible port>` declaration (none without `port=`).
fn flexible_decl(child: &Element) -> Option<FlexibleDecl> {
    let port = child.value("port")?;
    Some(FlexibleDecl {
        port: port.to_string(),
        dir: if child.value("dir") == Some("out") {
            PortDir::Out
        } else {
            PortDir::In
        },
        same_type: child.value("same-type") != Some("false"),
        min_count: child
            .value("min-count")
            .and_then(|v| v.parse().ok())
            .unwrap_or(0),
        max_count: child.value("max-count").and_then(|v| v.parse().ok()),
        span: child.value_span("port"),
    })
}

/// A data port declared by an `<in>`, `<out>`, `<sensor-…>` or `<controller-…>` child
/// (none for other children): sensor and controller ports belong to sense-control
/// module types, plain ones to the others.
fn data_port(
    set: &LibrarySet,
    visible: &[LibraryId],
    child: &Element,
    kind: ModuleKind,
    diags: &mut Diagnostics,
) -> Option<PortDecl> {
    let (dir, role) = match child.name.as_str() {
        "in" => (PortDir::In, PortRole::Plain),
        "out" => (PortDir::Out, PortRole::Plain),
        "sensor-in" => (PortDir::In, PortRole::Sensor),
        "sensor-out" => (PortDir::Out, PortRole::Sensor),
        "controller-in" => (PortDir::In, PortRole::Controller),
        "controller-out" => (PortDir::Out, PortRole::Controller),
        _ => return None,
    };
    let sensor_or_controller = matches!(role, PortRole::Sensor | PortRole::Controller);
    if sensor_or_controller != (kind == ModuleKind::SenseControl) {
        misplaced(
            child,
            if sensor_or_controller {
                "sensor and controller ports belong to kind=\"sense-control\" module types"
            } else {
                "a sense-control module type declares sensor-/controller- ports, not plain in/out"
            },
            diags,
        );
        return None;
    }
    port_decl(set, visible, child, dir, role, diags)
}

fn misplaced(child: &Element, why: &str, diags: &mut Diagnostics) {
    diags.push(
        Diagnostic::new(
            &m105_misplaced_element::CHECK,
            child.name_span,
            format!("<{}> does not fit this module type", child.name),
        )
        .label("misplaced here")
        .help(why.to_string()),
    );
}

pub(super) fn unique(
    names: &mut HashMap<String, Span>,
    name: &str,
    span: Span,
    diags: &mut Diagnostics,
) -> bool {
    if let Some(first) = names.get(name) {
        diags.push(
            Diagnostic::new(
                &m109_duplicate_name::CHECK,
                span,
                format!("`{name}` is declared twice in this module type"),
            )
            .label("second declaration")
            .secondary(*first, "first declaration")
            .help(
                "port and parameter names are unique within a module type, across all directions",
            ),
        );
        return false;
    }
    names.insert(name.to_string(), span);
    true
}

fn port_decl(
    set: &LibrarySet,
    visible: &[LibraryId],
    e: &Element,
    dir: PortDir,
    role: PortRole,
    diags: &mut Diagnostics,
) -> Option<PortDecl> {
    let name = e.value("name")?;
    let ty_text = e.value("type")?;
    let ty = match ty_text.strip_prefix('$') {
        Some(group) => PortType::SameAs(group.to_string()),
        None => PortType::Fixed(set.resolve_type(ty_text, e.value_span("type"), visible, diags)?),
    };
    Some(PortDecl {
        name: name.to_string(),
        dir,
        role,
        ty,
        unit: unit_attr(e, diags),
        required: e.value("required") == Some("true"),
        blocking_read: e.value("read") == Some("blocking"),
        read_timeout: super::steps::timeout(e, diags),
        merge: e.value("fan-in") == Some("merge"),
        span: e.value_span("name"),
    })
}
