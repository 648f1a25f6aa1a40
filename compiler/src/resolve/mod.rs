//! Resolver: from the syntax trees and the library tables to the [`Application`] IR.
//!
//! It builds the element tree (instantiating group types, each instance keeping the span
//! of its use), then resolves connections once every element exists, so a `<connect>` may
//! precede the modules it names.

use crate::checks::model::*;
use crate::diagnostic::{did_you_mean, Diagnostic};
use crate::ir::*;
use crate::library::{LibraryId, LibrarySet, PortDir};
use crate::load::{Loader, ModelFiles};
use crate::source::{FileId, Span};
use crate::syntax::Element;
use crate::values::parse_duration;
use hashbrown::{HashMap, HashSet};
use petgraph::graph::DiGraph;

mod connect;
mod module;
mod timing;

/// A `<connect>` waiting for the tree to be complete.
struct PendingConnect<'t> {
    scope: ElementId,
    element: &'t Element,
    instantiated_at: Option<Span>,
    visible: &'t [LibraryId],
}

pub(crate) struct Resolver<'r, 'l, 't> {
    pub loader: &'r mut Loader<'l>,
    pub libs: &'t LibrarySet,
    app: Application,
    local_group_types: HashMap<&'t str, (FileId, &'t Element)>,
    pending: Vec<PendingConnect<'t>>,
    /// Group types being instantiated (recursion guard), with their use sites.
    instantiating: Vec<(*const Element, Span)>,
    /// Names of elements not created because their definition was reported (an unknown
    /// type or library, a recursive or too deep group type), by scope: a path through
    /// one ends silently instead of adding "has no element" to the finding that says why.
    broken: HashSet<(ElementId, String)>,
    /// Groups of an unknown group type: what is inside them is unknown too.
    broken_groups: HashSet<ElementId>,
}

/// Resolves a loaded model. `used` are the libraries the application `<use>`s.
pub fn resolve(
    loader: &mut Loader<'_>,
    model: &ModelFiles,
    libs: &LibrarySet,
    used: &[LibraryId],
) -> Application {
    let root = &model.root;
    let app = Application {
        name: root.value("name").unwrap_or("").to_string(),
        span: root.name_span,
        elements: vec![ElementNode {
            kind: ElementKind::Application,
            name: String::new(),
            parent: None,
            name_span: root.name_span,
            span: root.span,
            instantiated_at: None,
            group_ports: Vec::new(),
            thread: None,
            part: None,
        }],
        connections: Vec::new(),
        graph: DiGraph::new(),
        nodes: HashMap::new(),
        children: HashMap::new(),
        resources: Vec::new(),
        profile: loader
            .options
            .profile
            .unwrap_or(match root.value("profile") {
                Some("finroc") => Profile::Finroc,
                _ => Profile::Generic,
            }),
        timing: Timing::default(),
        cut_off: HashSet::new(),
        ib2c_violations: root.value("ib2c-violations").map(str::to_string),
    };
    let mut r = Resolver {
        loader,
        libs,
        app,
        local_group_types: HashMap::new(),
        pending: Vec::new(),
        instantiating: Vec::new(),
        broken: HashSet::new(),
        broken_groups: HashSet::new(),
    };
    let mut files: Vec<(FileId, &Element)> = vec![(model.file, root)];
    files.extend(model.fragments.iter().map(|(f, e)| (*f, e)));
    let mut resources: HashMap<&str, Span> = HashMap::new();
    for (file, element) in &files {
        for gt in element.children_named("group-type") {
            let Some(name) = gt.value("name") else {
                continue;
            };
            if let Some((_, first)) = r.local_group_types.get(name) {
                let first = first.value_span("name");
                r.duplicate(
                    gt.value_span("name"),
                    first,
                    &format!("group type `{name}`"),
                );
            } else {
                r.local_group_types.insert(name, (*file, gt));
            }
        }
        for res in element.children_named("resource") {
            let Some(name) = res.value("name") else {
                continue;
            };
            if let Some(first) = resources.get(name) {
                r.duplicate(
                    res.value_span("name"),
                    *first,
                    &format!("resource `{name}`"),
                );
            } else {
                resources.insert(name, res.value_span("name"));
                r.app.resources.push(Resource {
                    name: name.to_string(),
                    span: res.value_span("name"),
                    level: res.value("level").and_then(|l| l.parse().ok()),
                    recursive: res.value("kind") == Some("recursive"),
                });
            }
        }
    }
    r.walk(ElementId(0), root, used, None, 0);
    r.application_timing(root);
    // Room for every connection, its edge and both ends up front: grown by doubling,
    // the vectors and the node table were copied ~18 times at 100,000 modules, and each
    // copy left its old block resident (B1 peak memory: a third of it was these copies).
    let pending = std::mem::take(&mut r.pending);
    r.app.connections.reserve_exact(pending.len());
    r.app.graph.reserve_edges(pending.len());
    r.app.graph.reserve_nodes(2 * pending.len());
    r.app.nodes.reserve(2 * pending.len());
    for pending in pending {
        r.resolve_connect(pending);
    }
    r.app
}

impl<'r, 'l, 't> Resolver<'r, 'l, 't> {
    /// `element` (in `scope`) is not created for a reason already reported.
    pub(super) fn broken(&mut self, scope: ElementId, element: &Element) {
        if let Some(name) = element.value("name") {
            self.broken.insert((scope, name.to_string()));
        }
    }

    fn duplicate(&mut self, span: Span, first: Span, what: &str) {
        self.loader.diags.push(
            Diagnostic::new(
                &m109_duplicate_name::CHECK,
                span,
                format!("{what} is defined twice"),
            )
            .label("second definition")
            .secondary(first, "first definition")
            .help("rename one of them; names are unique within their scope"),
        );
    }

    fn add_element(
        &mut self,
        parent: ElementId,
        element: &Element,
        kind: ElementKind,
        instantiated_at: Option<Span>,
    ) -> Option<ElementId> {
        let name = element.value("name")?.to_string();
        let id = ElementId(self.app.elements.len() as u32);
        let name_span = element.value_span("name");
        if let Some(existing) = self.app.child(parent, &name).as_ref() {
            let first = self.app.element(*existing).name_span;
            self.duplicate(name_span, first, &format!("`{name}`"));
            return None;
        }
        let p = self.app.element(parent);
        let (mut thread, mut part) = (p.thread, p.part);
        match kind {
            ElementKind::Thread { .. } => thread = Some(id),
            ElementKind::Part { .. } => part = Some(id),
            _ => {}
        }
        self.app.children.insert(
            crate::ir::ChildKey {
                parent,
                name: name.as_str().into(),
            },
            id,
        );
        self.app.elements.push(ElementNode {
            kind,
            name,
            parent: Some(parent),
            name_span,
            span: element.span,
            instantiated_at,
            group_ports: Vec::new(),
            thread,
            part,
        });
        Some(id)
    }

    fn walk(
        &mut self,
        scope: ElementId,
        element: &'t Element,
        visible: &'t [LibraryId],
        inst: Option<Span>,
        depth: usize,
    ) {
        for child in &element.children {
            match child.name.as_str() {
                "part" => {
                    let host = child
                        .attr("host")
                        .map(|a| (a.value.to_string(), a.value_span));
                    if let Some(id) =
                        self.add_element(scope, child, ElementKind::Part { host }, inst)
                    {
                        self.part_timing(id, child);
                        self.walk(id, child, visible, inst, depth);
                    }
                }
                "thread" => {
                    let period = self.thread_period(child);
                    let kind = ElementKind::Thread {
                        period,
                        pool: child
                            .value("pool")
                            .and_then(|p| p.parse().ok())
                            .filter(|n: &u32| *n >= 2),
                        data_trigger: child.value("trigger") == Some("data"),
                        continuous: child.value("trigger") == Some("continuous"),
                        wait: self.thread_wait(child),
                    };
                    if let Some(id) = self.add_element(scope, child, kind, inst) {
                        self.thread_timing(id, child);
                        self.walk(id, child, visible, inst, depth);
                    }
                }
                "group" => self.group(scope, child, visible, inst, depth),
                "module" => self.module(scope, child, visible, inst),
                "connect" => self.pending.push(PendingConnect {
                    scope,
                    element: child,
                    instantiated_at: inst,
                    visible,
                }),
                _ => {}
            }
        }
    }

    /// `wait=`: only a data-triggered container waits for data; on any other the
    /// attribute would silently do nothing, so it is a finding (M108).
    fn thread_wait(&mut self, thread: &Element) -> crate::ir::Wait {
        let Some(wait) = thread.attr("wait") else {
            return crate::ir::Wait::default();
        };
        if thread.value("trigger") != Some("data") {
            self.loader.diags.push(
                Diagnostic::new(
                    &m108_invalid_attribute_value::CHECK,
                    wait.name_span,
                    format!(
                        "`wait` applies only to data-triggered containers, and `{}` is not one",
                        thread.value("name").unwrap_or("")
                    ),
                )
                .label("has no effect here")
                .help("remove `wait`, or add trigger=\"data\" if the container should run when data arrives"),
            );
        }
        crate::ir::Wait::parse(&wait.value).unwrap_or_default()
    }

    fn thread_period(&mut self, thread: &Element) -> Option<f64> {
        let period = thread.attr("period");
        let trigger = thread.attr("trigger");
        let bad = |msg: String, span: Span, help: &str| {
            Diagnostic::new(&m108_invalid_attribute_value::CHECK, span, msg)
                .label("here")
                .help(help.to_string())
        };
        match (period, trigger) {
            (Some(_), Some(t)) => {
                self.loader.diags.push(bad(
                    "a thread container is either periodic or triggered, not both".into(),
                    t.name_span,
                    "remove `trigger` or `period`",
                ));
                None
            }
            (None, None) => {
                self.loader.diags.push(bad(
                    format!("thread container `{}` has neither `period` nor `trigger`", thread.value("name").unwrap_or("")),
                    thread.name_span,
                    "add period=\"10ms\" (periodic), trigger=\"data\" (runs when inputs receive data) or trigger=\"continuous\" (cycles back to back)",
                ));
                None
            }
            (Some(p), None) => match parse_duration(&p.value) {
                Ok(s) if s > 0.0 && s <= 60.0 => Some(s),
                Ok(_) => {
                    self.loader.diags.push(bad(
                        format!("period `{}` is outside 0 < period <= 60 s", p.value),
                        p.value_span,
                        "use a period such as `10ms` or `1s`",
                    ));
                    None
                }
                Err(_) => {
                    self.loader.diags.push(bad(
                        format!("`{}` is not a duration", p.value),
                        p.value_span,
                        "write e.g. `10ms`, `1.5s`, `250us` or `PT0.04S`",
                    ));
                    None
                }
            },
            (None, Some(_)) => None,
        }
    }

    fn group(
        &mut self,
        scope: ElementId,
        child: &'t Element,
        visible: &'t [LibraryId],
        inst: Option<Span>,
        depth: usize,
    ) {
        let Some(type_attr) = child.attr("type") else {
            if let Some(id) = self.add_element(scope, child, ElementKind::Group, inst) {
                self.walk(id, child, visible, inst, depth);
                self.group_ports(id, child, visible);
            }
            return;
        };
        let Some((def, def_visible)) =
            self.find_group_type(&type_attr.value, type_attr.value_span, visible)
        else {
            // Keep the group so that paths to it resolve; paths into it end silently
            // (its content is unknown, which the unknown type already says).
            if let Some(id) = self.add_element(scope, child, ElementKind::Group, inst) {
                self.broken_groups.insert(id);
            }
            return;
        };
        let use_span = type_attr.value_span;
        if let Some(pos) = self
            .instantiating
            .iter()
            .position(|(d, _)| std::ptr::eq(*d, def))
        {
            let mut d = Diagnostic::new(
                &m117_recursive_group_type::CHECK,
                use_span,
                format!(
                    "group type `{}` contains an instance of itself",
                    type_attr.value
                ),
            )
            .label("instantiated again here");
            for (_, span) in &self.instantiating[pos..] {
                d = d.secondary(*span, "instantiated here");
            }
            self.loader
                .diags
                .push(d.help("break the recursion: a group type cannot contain itself"));
            self.broken(scope, child);
            return;
        }
        if depth >= self.loader.options.limits.max_instance_depth {
            self.loader.diags.push(
                Diagnostic::new(
                    &m116_limit_exceeded::CHECK,
                    use_span,
                    format!(
                        "group types nest more than {} deep",
                        self.loader.options.limits.max_instance_depth
                    ),
                )
                .label("one level too many")
                .help("flatten the group structure"),
            );
            self.broken(scope, child);
            return;
        }
        let Some(id) = self.add_element(scope, child, ElementKind::Group, inst) else {
            return;
        };
        self.instantiating.push((def as *const Element, use_span));
        // Elements of the definition point into it and remember this use.
        let inner_inst = Some(inst.unwrap_or(use_span));
        self.walk(id, def, def_visible, inner_inst, depth + 1);
        self.group_ports(id, def, def_visible);
        self.instantiating.pop();
    }

    /// `local.Name` or `lib.Name`: the definition and the libraries its content may use.
    fn find_group_type(
        &mut self,
        name: &str,
        span: Span,
        visible: &'t [LibraryId],
    ) -> Option<(&'t Element, &'t [LibraryId])> {
        let libs = self.libs;
        let (lib, short) = name.split_once('.').unwrap_or(("", name));
        if lib == "local" {
            if let Some((_, def)) = self.local_group_types.get(short) {
                return Some((def, visible));
            }
            let names: Vec<&str> = self.local_group_types.keys().copied().collect();
            self.unknown_group_type(
                name,
                span,
                did_you_mean(short, names).map(|s| format!("local.{s}")),
            );
            return None;
        }
        if let Some(id) = libs.by_name.get(lib) {
            let library = libs.get(*id);
            if let Some(gt) = library.group_types.iter().find(|g| g.name == short) {
                if !visible.contains(id) {
                    self.not_used(lib, span);
                }
                return Some((&gt.element, &library.visible));
            }
            let names = library.group_types.iter().map(|g| g.name.as_str());
            let hint = did_you_mean(short, names).map(|s| format!("{lib}.{s}"));
            self.unknown_group_type(name, span, hint);
            return None;
        }
        self.unknown_group_type(name, span, None);
        None
    }

    fn unknown_group_type(&mut self, name: &str, span: Span, hint: Option<String>) {
        let d = Diagnostic::new(
            &m111_unknown_type::CHECK,
            span,
            format!("unknown group type `{name}`"),
        )
        .label("no such group type");
        self.loader.diags.push(match hint {
            Some(h) => d.help(format!("did you mean `{h}`?")),
            None => d.help(
                "group types are `local.Name` (this file and its includes) or `library.Name`",
            ),
        });
    }

    pub(crate) fn not_used(&mut self, lib: &str, span: Span) {
        self.loader.diags.push(
            Diagnostic::new(
                &crate::checks::libraries::l104_library_not_used::CHECK,
                span,
                format!("library `{lib}` is loaded but not used by this file"),
            )
            .label("library not in scope")
            .help(format!("add <use library=\"{lib}\"/>")),
        );
    }

    fn group_ports(&mut self, id: ElementId, def: &'t Element, visible: &'t [LibraryId]) {
        let mut ports = Vec::new();
        for p in def.children_named("port") {
            let (Some(name), Some(ty)) = (p.value("name"), p.value("type")) else {
                continue;
            };
            if let Some(first) = ports.iter().find(|x: &&GroupPort| x.name == name) {
                let first = first.span;
                self.duplicate(p.value_span("name"), first, &format!("port `{name}`"));
                continue;
            }
            let Some(ty) =
                self.libs
                    .resolve_type(ty, p.value_span("type"), visible, self.loader.diags)
            else {
                continue;
            };
            ports.push(GroupPort {
                name: name.to_string(),
                dir: if p.value("dir") == Some("out") {
                    PortDir::Out
                } else {
                    PortDir::In
                },
                ty,
                unit: crate::library::unit_attr(p, self.loader.diags),
                span: p.value_span("name"),
            });
        }
        for port in &ports {
            if let Some(child) = self.app.child(id, &port.name).as_ref() {
                let first = self.app.element(*child).name_span;
                self.duplicate(port.span, first, &format!("`{}`", port.name));
            }
        }
        self.app.elements[id.0 as usize].group_ports = ports;
    }
}
