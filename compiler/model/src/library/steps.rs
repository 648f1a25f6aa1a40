//! What a module type does that can wait: its clients and services (as ports, so that
//! `<connect>` resolves them like any other port), its lock slots, and the steps of its
//! activities and service bodies in program order. Read by the deadlock analysis
//! (`ferroc_deadlock`); see `docs/model-language-additions.md`.

use super::module_type::{unique, ModuleType, PortDecl, PortDir, PortRole, PortType};
use super::{LibraryId, LibrarySet};
use ferroc_diagnostics::diagnostic::{did_you_mean, Diagnostic, Diagnostics};
use ferroc_diagnostics::source::Span;
use ferroc_syntax::checks::m108_invalid_attribute_value;
use ferroc_syntax::Element;
use ferroc_values::types::Type;
use ferroc_values::values::parse_duration;
use hashbrown::HashMap;

/// A `timeout` attribute: absent, `none`, or a duration in seconds.
pub type Timeout = Option<f64>;

#[derive(Clone, Debug)]
pub struct ClientDecl {
    pub name: String,
    /// Index of its port in [`ModuleType::ports`].
    pub port: usize,
    /// `blocking="false"` makes every call asynchronous unless a step says `mode="sync"`.
    pub blocking: bool,
    pub timeout: Timeout,
    /// `response=`: what a call returns (`None` when it did not resolve; reported).
    pub response: Option<Type>,
    /// `response-via="caller"`: the response is processed by the caller's own thread
    /// container (ROS 2 callback groups), not handed to the blocked caller directly.
    pub response_via_caller: bool,
    pub span: Span,
}

#[derive(Clone, Debug)]
pub struct ServiceDecl {
    pub name: String,
    pub port: usize,
    /// `executes="caller"`: the body runs inline in the caller's thread.
    pub inline: bool,
    /// `response=`: what a call returns (`None` when it did not resolve; reported).
    pub response: Option<Type>,
    /// `executes` was written (a profile may only change the default).
    pub executes_explicit: bool,
    pub body: Vec<StepDecl>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum StepOp {
    Lock {
        slot: usize,
    },
    Unlock {
        slot: usize,
    },
    /// Reads input port `port` (index into `ports`); waits only for a blocking read.
    Read {
        port: usize,
    },
    /// Writes output port `port`, `count` items; `optional`: may skip.
    Write {
        port: usize,
        count: u32,
        optional: bool,
    },
    /// A call through client `client` (index into `clients`); `sync` after defaults.
    Call {
        client: usize,
        sync: bool,
    },
    Await {
        client: usize,
    },
}

#[derive(Clone, Debug)]
pub struct StepDecl {
    pub op: StepOp,
    /// The timeout of this step: the step's own attribute, else the declaration's
    /// (the port's or client's); `None` waits forever.
    pub timeout: Timeout,
    pub span: Span,
}

#[derive(Clone, Debug)]
pub struct ActivityDecl {
    /// `update`, `sense` or `control`.
    pub name: String,
    pub steps: Vec<StepDecl>,
    /// Declared with `<activity>` (false: the default derived from the interface).
    pub explicit: bool,
    pub span: Span,
}

/// Clients (outputs) and services (inputs) become ports of the module type.
pub(super) fn add_rpc_ports(
    set: &LibrarySet,
    visible: &[LibraryId],
    element: &Element,
    mt: &mut ModuleType,
    names: &mut HashMap<String, Span>,
    diags: &mut Diagnostics,
) {
    for child in &element.children {
        let (dir, role) = match child.name.as_str() {
            "client" => (PortDir::Out, PortRole::Client),
            "service" => (PortDir::In, PortRole::Service),
            _ => continue,
        };
        let (Some(name), Some(request)) = (child.value("name"), child.value("request")) else {
            continue;
        };
        let Some(ty) = set.resolve_type(request, child.value_span("request"), visible, diags)
        else {
            continue;
        };
        let response = child
            .value("response")
            .and_then(|r| set.resolve_type(r, child.value_span("response"), visible, diags));
        let span = child.value_span("name");
        if !unique(names, name, span, diags) {
            continue;
        }
        let port = mt.ports.len();
        mt.ports.push(PortDecl {
            name: name.to_string(),
            dir,
            role,
            ty: PortType::Fixed(ty),
            unit: None,
            required: false,
            blocking_read: false,
            read_timeout: None,
            // Many clients may call one service: not "last writer wins".
            merge: role == PortRole::Service,
            span,
        });
        if role == PortRole::Client {
            mt.clients.push(ClientDecl {
                name: name.to_string(),
                port,
                blocking: child.value("blocking") != Some("false"),
                timeout: timeout(child, diags),
                response_via_caller: child.value("response-via") == Some("caller"),
                response,
                span,
            });
        } else {
            mt.services.push(ServiceDecl {
                name: name.to_string(),
                port,
                inline: child.value("executes") == Some("caller"),
                response,
                executes_explicit: child.attr("executes").is_some(),
                body: Vec::new(),
                span,
            });
        }
    }
}

/// Lock slots, activities and service bodies; after the ports are indexed.
pub(super) fn build(element: &Element, mt: &mut ModuleType, diags: &mut Diagnostics) {
    for locks in element.children_named("locks") {
        let sequence: Vec<String> = words(locks, "order").into_iter().map(|(s, _)| s).collect();
        if sequence.len() > 1 {
            mt.lock_orders.push(sequence);
        }
        for (slot, span) in words(locks, "order") {
            if !mt.lock_slots.iter().any(|(s, _)| *s == slot) {
                mt.lock_slots.push((slot, span));
            }
        }
    }
    // Slots used only by steps are slots too (bound by name unless `<bind>` says otherwise).
    let step_elements = element
        .children_named("activity")
        .chain(element.children_named("service"))
        .flat_map(|e| e.children.iter());
    for s in step_elements {
        if let (true, Some(slot)) = (
            matches!(s.name.as_str(), "lock" | "unlock"),
            s.value("slot"),
        ) {
            if !mt.lock_slots.iter().any(|(x, _)| x == slot) {
                mt.lock_slots.push((slot.to_string(), s.value_span("slot")));
            }
        }
    }
    let service_elements: Vec<&Element> = element.children_named("service").collect();
    for i in 0..mt.services.len() {
        let name = mt.services[i].name.clone();
        if let Some(e) = service_elements
            .iter()
            .find(|e| e.value("name") == Some(&name))
        {
            mt.services[i].body = steps(e, mt, diags);
        }
    }
    for a in element.children_named("activity") {
        let name = a.value("name").unwrap_or("update").to_string();
        let steps = steps(a, mt, diags);
        mt.activities.push(ActivityDecl {
            name,
            steps,
            explicit: true,
            span: a.name_span,
        });
    }
    if mt.activities.is_empty() {
        let default = default_activity(mt);
        mt.activities.push(default);
    }
}

/// Without `<activity>`: read the blocking inputs, take and release the lock slots in
/// order, call the clients, write the outputs — the shape of a plain update.
fn default_activity(mt: &ModuleType) -> ActivityDecl {
    let span = mt.span;
    let step = |op| StepDecl {
        op,
        timeout: None,
        span,
    };
    let mut steps = Vec::new();
    for (i, p) in mt.ports.iter().enumerate() {
        if p.dir == PortDir::In && p.blocking_read {
            steps.push(StepDecl {
                timeout: p.read_timeout,
                ..step(StepOp::Read { port: i })
            });
        }
    }
    for slot in 0..mt.lock_slots.len() {
        steps.push(StepDecl {
            span: mt.lock_slots[slot].1,
            ..step(StepOp::Lock { slot })
        });
    }
    for slot in (0..mt.lock_slots.len()).rev() {
        steps.push(step(StepOp::Unlock { slot }));
    }
    for (i, c) in mt.clients.iter().enumerate() {
        steps.push(StepDecl {
            timeout: c.timeout,
            span: c.span,
            ..step(StepOp::Call {
                client: i,
                sync: c.blocking,
            })
        });
    }
    for (i, p) in mt.ports.iter().enumerate() {
        if p.dir == PortDir::Out
            && matches!(
                p.role,
                PortRole::Plain | PortRole::Sensor | PortRole::Controller
            )
        {
            steps.push(step(StepOp::Write {
                port: i,
                count: 1,
                optional: false,
            }));
        }
    }
    ActivityDecl {
        name: "update".into(),
        steps,
        explicit: false,
        span,
    }
}

fn steps(parent: &Element, mt: &ModuleType, diags: &mut Diagnostics) -> Vec<StepDecl> {
    let mut out = Vec::new();
    for s in &parent.children {
        let span = s.name_span;
        let op = match s.name.as_str() {
            "lock" | "unlock" => {
                let Some(slot) = s.value("slot") else {
                    continue;
                };
                let Some(i) = mt.lock_slots.iter().position(|(x, _)| x == slot) else {
                    continue;
                };
                if s.name == "lock" {
                    StepOp::Lock { slot: i }
                } else {
                    StepOp::Unlock { slot: i }
                }
            }
            "read" | "write" => {
                let want = if s.name == "read" {
                    PortDir::In
                } else {
                    PortDir::Out
                };
                let Some(port) = port_ref(s, mt, want, diags) else {
                    continue;
                };
                if s.name == "read" {
                    StepOp::Read { port }
                } else {
                    StepOp::Write {
                        port,
                        count: s.value("count").and_then(|c| c.parse().ok()).unwrap_or(1),
                        optional: s.value("optional") == Some("true"),
                    }
                }
            }
            "call" | "await" => {
                let Some(name) = s.value("client") else {
                    continue;
                };
                let Some(client) = mt.clients.iter().position(|c| c.name == name) else {
                    unknown(
                        s,
                        "client",
                        name,
                        mt.clients.iter().map(|c| c.name.as_str()),
                        diags,
                    );
                    continue;
                };
                if s.name == "await" {
                    StepOp::Await { client }
                } else {
                    let sync = match s.value("mode") {
                        Some("sync") => true,
                        Some("async") => false,
                        _ => mt.clients[client].blocking,
                    };
                    StepOp::Call { client, sync }
                }
            }
            _ => continue,
        };
        let declared = match &op {
            StepOp::Read { port } => mt.ports[*port].read_timeout,
            StepOp::Call { client, .. } | StepOp::Await { client } => mt.clients[*client].timeout,
            _ => None,
        };
        let timeout = if s.attr("timeout").is_some() {
            timeout(s, diags)
        } else {
            declared
        };
        out.push(StepDecl { op, timeout, span });
    }
    out
}

fn port_ref(s: &Element, mt: &ModuleType, dir: PortDir, diags: &mut Diagnostics) -> Option<usize> {
    let name = s.value("port")?;
    match mt.port_index.get(name) {
        Some(&i) if mt.ports[i].dir == dir => Some(i),
        _ => {
            let candidates = mt
                .ports
                .iter()
                .filter(|p| p.dir == dir)
                .map(|p| p.name.as_str());
            let what = if dir == PortDir::In {
                "input"
            } else {
                "output"
            };
            unknown(s, what, name, candidates, diags);
            None
        }
    }
}

fn unknown<'a>(
    s: &Element,
    what: &str,
    name: &str,
    candidates: impl Iterator<Item = &'a str>,
    diags: &mut Diagnostics,
) {
    let attr = if what == "client" { "client" } else { "port" };
    let mut d = Diagnostic::new(
        &m108_invalid_attribute_value::CHECK,
        s.value_span(attr),
        format!("this module type has no {what} `{name}`"),
    )
    .label(format!("not an {what} of this module type").replace("an client", "a client"));
    d = match did_you_mean(name, candidates) {
        Some(c) => d.help(format!("did you mean `{c}`?")),
        None => d.help(format!("name one of the module type's {what}s")),
    };
    diags.push(d);
}

/// `timeout="none"` or a duration; an unparsable value is reported and treated as none.
pub(super) fn timeout(e: &Element, diags: &mut Diagnostics) -> Timeout {
    let a = e.attr("timeout")?;
    if a.value.trim() == "none" {
        return None;
    }
    match parse_duration(a.value) {
        Ok(s) if s >= 0.0 => Some(s),
        _ => {
            diags.push(
                Diagnostic::new(
                    &m108_invalid_attribute_value::CHECK,
                    a.value_span,
                    format!("`{}` is not a timeout", a.value),
                )
                .label("expected a duration or `none`")
                .help("write e.g. timeout=\"50ms\", or timeout=\"none\" to wait forever"),
            );
            None
        }
    }
}

/// A duration attribute such as `budget="2ms"` (seconds, with the value's span); an
/// unparsable value is reported (M108) and ignored.
pub fn duration_attr(e: &Element, attr: &str, diags: &mut Diagnostics) -> Option<(f64, Span)> {
    let a = e.attr(attr)?;
    match parse_duration(a.value) {
        Ok(s) => Some((s, a.value_span)),
        Err(_) => {
            diags.push(
                Diagnostic::new(
                    &m108_invalid_attribute_value::CHECK,
                    a.value_span,
                    format!("`{}` is not a duration", a.value),
                )
                .label("expected a duration")
                .help(format!("write e.g. {attr}=\"2ms\", `250us` or `PT0.002S`")),
            );
            None
        }
    }
}

/// Space-separated identifiers of an attribute, each with its own span.
fn words(e: &Element, attr: &str) -> Vec<(String, Span)> {
    let Some(a) = e.attr(attr) else {
        return Vec::new();
    };
    let base = a.value_span;
    let text = a.value;
    text.split_whitespace()
        .map(|w| {
            let start = base.start + (w.as_ptr() as usize - text.as_ptr() as usize) as u32;
            let end = (start + w.len() as u32).min(base.end.max(start));
            (w.to_string(), Span { start, end, ..base })
        })
        .collect()
}
