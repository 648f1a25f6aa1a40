//! Resolver: from the syntax trees and the library tables to the [`Application`] IR.
//!
//! It builds the element tree (instantiating group types, each instance keeping the span
//! of its use), then resolves connections once every element exists, so a `<connect>` may
//! precede the modules it names.

use crate::checks::model::*;
use crate::diagnostic::Diagnostic;
use crate::ir::*;
use crate::library::{LibraryId, LibrarySet};
use crate::load::{Loader, ModelFiles};
use crate::source::{FileId, Span};
use crate::syntax::Element;
use hashbrown::{HashMap, HashSet};
use petgraph::graph::DiGraph;

mod connect;
mod group;
mod module;
mod timing;
mod tree;

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
        nodes: NodeTable::default(),
        children: Children::default(),
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
    // Room for the elements written in the files (instances of group types add more,
    // and those grow the vector as usual): grown by doubling, the last copy would hold
    // room for up to twice the elements of a large model (B1).
    let written: usize = files.iter().map(|(_, e)| tree_elements(e)).sum();
    r.app.elements.reserve_exact(written);
    r.walk(ElementId(0), root, used, None, 0);
    r.application_timing(root);
    // Room for every connection, its edge and both ends up front: grown by doubling,
    // the vectors and the node table were copied ~18 times at 100,000 modules, and each
    // copy left its old block resident (B1 peak memory: a third of it was these copies).
    let pending = std::mem::take(&mut r.pending);
    r.app.connections.reserve_exact(pending.len());
    r.app.graph.reserve_edges(pending.len());
    r.app.graph.reserve_nodes(2 * pending.len());
    r.app.nodes.reserve(&r.app.graph, 2 * pending.len());
    for pending in pending {
        r.resolve_connect(pending);
    }
    r.app
}

/// Parts, thread containers, groups and modules written below `e` (not counting what
/// instances of group types bring).
fn tree_elements(e: &Element) -> usize {
    e.children
        .iter()
        .filter(|c| matches!(c.name.as_str(), "part" | "thread" | "group" | "module"))
        .map(|c| 1 + tree_elements(c))
        .sum()
}

impl<'r, 'l, 't> Resolver<'r, 'l, 't> {
    /// `element` (in `scope`) is not created for a reason already reported.
    pub(super) fn broken(&mut self, scope: ElementId, element: &Element) {
        if let Some(name) = element.value("name") {
            self.broken.insert((scope, name.to_string()));
        }
    }

    pub(super) fn duplicate(&mut self, span: Span, first: Span, what: &str) {
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
}
