//! Resolver: from the syntax trees and the library tables to the [`Application`] IR.
//!
//! It builds the element tree (instantiating group types, each instance keeping the span
//! of its use), then resolves connections once every element exists, so a `<connect>` may
//! precede the modules it names.

use crate::checks::*;
use crate::ir::*;
use crate::library::{LibraryId, LibrarySet};
use crate::load::{Loader, ModelFiles};
use ferroc_diagnostics::diagnostic::Diagnostic;
use ferroc_diagnostics::source::{FileId, Span};
use ferroc_syntax::Element;
use hashbrown::{HashMap, HashSet};
use petgraph::graph::DiGraph;

mod connect;
mod group;
mod module;
mod ports;
mod ros2;
mod shm;
mod timing;
mod tree;

/// A `<connect>` waiting for the tree to be complete: 16 bytes, for the ~210,000 of a
/// 100,000-module model are all alive at the end of resolving, the checker's peak of
/// memory (B1). What the connections of one group share is in [`Context`].
struct PendingConnect<'t> {
    element: &'t Element,
    scope: ElementId,
    /// Index into `Resolver::contexts`.
    context: u32,
}

/// The group type instance a `<connect>` comes from and the libraries visible there.
#[derive(Clone, Copy)]
struct Context<'t> {
    instantiated_at: Option<Span>,
    visible: &'t [LibraryId],
}

impl Context<'_> {
    fn same(&self, other: &Context<'_>) -> bool {
        self.instantiated_at == other.instantiated_at && std::ptr::eq(self.visible, other.visible)
    }
}

pub(crate) struct Resolver<'r, 'l, 't> {
    pub loader: &'r mut Loader<'l>,
    pub libs: &'t LibrarySet,
    app: Application,
    local_group_types: HashMap<&'t str, (FileId, &'t Element)>,
    pending: Vec<PendingConnect<'t>>,
    /// The contexts of `pending`, each once for a run of connections that share it.
    contexts: Vec<Context<'t>>,
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
    let app = empty_application(loader, root);
    let mut r = Resolver {
        loader,
        libs,
        app,
        local_group_types: HashMap::new(),
        pending: Vec::new(),
        contexts: Vec::new(),
        instantiating: Vec::new(),
        broken: HashSet::new(),
        broken_groups: HashSet::new(),
    };
    let mut files: Vec<(FileId, &Element)> = vec![(model.file, root)];
    files.extend(model.fragments.iter().map(|(f, e)| (*f, e)));
    let mut resources: HashMap<&str, Span> = HashMap::new();
    for (file, element) in &files {
        r.declare_group_types(*file, element);
        r.declare_resources(element, &mut resources);
    }
    r.reserve_for_walk(&files);
    r.walk(ElementId(0), root, used, None, 0);
    r.application_timing(root);
    r.external_ros2(root);
    r.ros2_interfaces(root);
    r.resolve_pending();
    r.app
}

/// The application of `root` with its root element only.
fn empty_application(loader: &Loader<'_>, root: &Element) -> Application {
    Application {
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
        ros2: Ros2::default(),
        shared_memory: HashMap::new(),
        ib2c_violations: root.value("ib2c-violations").map(str::to_string),
        seed: root.value("seed").and_then(|s| s.parse().ok()),
    }
}

impl<'t> Resolver<'_, '_, 't> {
    /// The `<group-type>`s a model file defines (a name defined twice is reported).
    fn declare_group_types(&mut self, file: FileId, element: &'t Element) {
        for gt in element.children_named("group-type") {
            let Some(name) = gt.value("name") else {
                continue;
            };
            if let Some((_, first)) = self.local_group_types.get(name) {
                let first = first.value_span("name");
                self.duplicate(
                    gt.value_span("name"),
                    first,
                    &format!("group type `{name}`"),
                );
            } else {
                self.local_group_types.insert(name, (file, gt));
            }
        }
    }

    /// The `<resource>`s a model file declares; `seen` holds those of the files before.
    fn declare_resources(&mut self, element: &'t Element, seen: &mut HashMap<&'t str, Span>) {
        for res in element.children_named("resource") {
            let Some(name) = res.value("name") else {
                continue;
            };
            if let Some(first) = seen.get(name) {
                self.duplicate(
                    res.value_span("name"),
                    *first,
                    &format!("resource `{name}`"),
                );
            } else {
                seen.insert(name, res.value_span("name"));
                self.app.resources.push(Resource {
                    name: name.to_string(),
                    span: res.value_span("name"),
                    level: res.value("level").and_then(|l| l.parse().ok()),
                    recursive: res.value("kind") == Some("recursive"),
                });
            }
        }
    }

    /// Room for the elements and `<connect>`s the walk will meet, those of local group
    /// type instances included: grown by doubling, the element vector's last copy held
    /// room for up to twice the elements, and the copies stayed resident (B1: at
    /// 100,000 modules, where a quarter of the groups are instances, the walk's
    /// resident memory was three times what it kept).
    fn reserve_for_walk(&mut self, files: &[(FileId, &'t Element)]) {
        let mut expected = Expected::new(&self.local_group_types);
        let (elements, connects) = files.iter().fold((0usize, 0usize), |(n, c), (_, e)| {
            let (n2, c2) = expected.below(e);
            (n.saturating_add(n2), c.saturating_add(c2))
        });
        self.app.elements.reserve_exact(elements);
        self.pending.reserve_exact(connects);
    }

    /// Resolves the `<connect>`s collected by the walk, now that every element exists.
    /// Room for every connection, its edge and both ends up front: grown by doubling,
    /// the vectors and the node table were copied ~18 times at 100,000 modules, and
    /// each copy left its old block resident (B1 peak memory: a third of it was these
    /// copies).
    fn resolve_pending(&mut self) {
        let pending = std::mem::take(&mut self.pending);
        self.app.connections.reserve_exact(pending.len());
        self.app.graph.reserve_edges(pending.len());
        self.app.graph.reserve_nodes(2 * pending.len());
        self.app.nodes.reserve(&self.app.graph, 2 * pending.len());
        for pending in pending {
            self.resolve_connect(pending);
        }
    }
}

/// How many elements (parts, thread containers, groups, modules) and `<connect>`s the
/// walk will create, to reserve room for them. Instances of local group types count
/// their definition's content; each definition is counted once (a definition that
/// contains itself, reported by the walk, counts as empty inside itself). Only an
/// estimate: library group types are not counted, and the counts are capped so that a
/// model of many nested instances reserves no more than a few times its own size.
struct Expected<'a, 't> {
    local: &'a HashMap<&'t str, (FileId, &'t Element)>,
    definitions: HashMap<*const Element, (usize, usize)>,
}

impl<'a, 't> Expected<'a, 't> {
    /// Room at most this many times what the files write (plus a little).
    const CAP: usize = 4;

    fn new(local: &'a HashMap<&'t str, (FileId, &'t Element)>) -> Self {
        Expected {
            local,
            definitions: HashMap::new(),
        }
    }

    /// Elements and `<connect>`s below `e`, capped.
    fn below(&mut self, e: &Element) -> (usize, usize) {
        let (elements, connects) = self.count(e);
        let (written, written_connects) = written(e);
        let cap = |n: usize, w: usize| n.min(w.saturating_mul(Self::CAP).saturating_add(1024));
        (cap(elements, written), cap(connects, written_connects))
    }

    fn count(&mut self, e: &Element) -> (usize, usize) {
        let (mut elements, mut connects) = (0usize, 0usize);
        for c in e.children.iter() {
            let (n, k) = match c.name.as_str() {
                "connect" => (0, 1),
                "part" | "thread" | "module" => plus_one(self.count(c)),
                "group" => {
                    let local = (c.value("type"))
                        .and_then(|t| t.strip_prefix("local."))
                        .and_then(|t| self.local.get(t));
                    match local {
                        Some(&(_, def)) => plus_one(self.definition(def)),
                        None => plus_one(self.count(c)),
                    }
                }
                _ => (0, 0),
            };
            elements = elements.saturating_add(n);
            connects = connects.saturating_add(k);
        }
        (elements, connects)
    }

    fn definition(&mut self, def: &Element) -> (usize, usize) {
        let key: *const Element = def;
        if let Some(&n) = self.definitions.get(&key) {
            return n;
        }
        self.definitions.insert(key, (0, 0));
        let n = self.count(def);
        self.definitions.insert(key, n);
        n
    }
}

fn plus_one((elements, connects): (usize, usize)) -> (usize, usize) {
    (elements.saturating_add(1), connects)
}

/// Elements and `<connect>`s written below `e` (instances not counted).
fn written(e: &Element) -> (usize, usize) {
    e.children
        .iter()
        .fold((0, 0), |(n, k), c| match c.name.as_str() {
            "connect" => (n, k + 1),
            "part" | "thread" | "group" | "module" => {
                let (n2, k2) = written(c);
                (n + 1 + n2, k + k2)
            }
            _ => (n, k),
        })
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
                &crate::checks::l104_library_not_used::CHECK,
                span,
                format!("library `{lib}` is loaded but not used by this file"),
            )
            .label("library not in scope")
            .help(format!("add <use library=\"{lib}\"/>")),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ferroc_syntax::xml::parse;

    /// The room reserved for the walk: local group type instances count their
    /// definition's content (nested instances too), a group type that contains itself
    /// (reported by the walk) stops the count instead of recursing, and `<port>`,
    /// `<param>` and the like are not elements of the tree.
    #[test]
    fn expected_counts_instances_of_local_group_types() {
        let text = r#"<application name="a" version="1">
            <group-type name="F">
                <port name="i" dir="in" type="f64"/>
                <module name="m" type="x.Y"><param name="p">1</param></module>
                <group name="h" type="local.G"/>
                <connect from="a" to="b"/>
            </group-type>
            <group-type name="G">
                <module name="n" type="x.Y"/>
                <connect from="a" to="b"/><connect from="a" to="c"/>
            </group-type>
            <group-type name="R"><group name="r" type="local.R"/></group-type>
            <part name="p"><thread name="t" period="1ms">
                <group name="g1" type="local.F"/><group name="g2" type="local.F"/>
                <group name="g3" type="local.R"/><group name="g4" type="lib.Other"/>
                <group name="g5"><module name="k" type="x.Y"/></group>
            </thread></part>
            <connect from="x" to="y"/>
        </application>"#;
        let root = parse(FileId(0), text, 64).unwrap();
        let local: HashMap<&str, (FileId, &Element)> = root
            .children_named("group-type")
            .map(|g| (g.value("name").unwrap(), (FileId(0), g)))
            .collect();
        // p, t; g1 and g2 with m, h and n each; g3 with r; g4; g5 with k.
        let elements = 2 + 2 * 4 + 2 + 1 + 2;
        // Three in each instance of F, one of the application.
        let connects = 2 * 3 + 1;
        assert_eq!(Expected::new(&local).below(&root), (elements, connects));
        // Written: p, t, g1–g5, k; the cap allows four times that and a little more.
        assert_eq!(written(&root), (8, 1));
    }

    /// ~210,000 of them are alive at the checker's peak of memory on a 100,000-module
    /// model (B1).
    #[test]
    fn a_pending_connect_is_two_words() {
        assert_eq!(std::mem::size_of::<PendingConnect<'_>>(), 16);
    }
}
