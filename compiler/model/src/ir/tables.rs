//! The two lookup tables of the [`Application`](super::Application): named children and
//! graph nodes. Each holds only ids and finds the key (a parent and a name, an
//! endpoint) in the element or node the id names, so no key is stored twice (B1).

use super::{ElementId, ElementNode, Endpoint};
use petgraph::graph::{DiGraph, NodeIndex};
use std::hash::BuildHasher;

/// The graph node of each connected endpoint: a hash table of node indices hashed by the
/// endpoint the node holds (4 bytes an entry instead of 16 for a map of copies; B1).
#[derive(Default)]
pub struct NodeTable {
    table: hashbrown::HashTable<NodeIndex>,
    hasher: hashbrown::DefaultHashBuilder,
}

impl std::fmt::Debug for NodeTable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "NodeTable({} entries)", self.table.len())
    }
}

impl NodeTable {
    fn hash(&self, ep: &Endpoint) -> u64 {
        self.hasher.hash_one(ep)
    }

    /// Room for `n` more endpoints.
    pub fn reserve(&mut self, graph: &DiGraph<Endpoint, usize>, n: usize) {
        let hasher = &self.hasher;
        self.table.reserve(n, |&i| hasher.hash_one(graph[i]));
    }

    /// The node of `ep`, if it has one.
    pub fn get(&self, graph: &DiGraph<Endpoint, usize>, ep: &Endpoint) -> Option<NodeIndex> {
        self.table
            .find(self.hash(ep), |&i| graph[i] == *ep)
            .copied()
    }

    /// The node of `ep`, added to `graph` if it has none yet.
    pub fn get_or_add(&mut self, graph: &mut DiGraph<Endpoint, usize>, ep: Endpoint) -> NodeIndex {
        if let Some(n) = self.get(graph, &ep) {
            return n;
        }
        let n = graph.add_node(ep);
        let hash = self.hash(&ep);
        let hasher = &self.hasher;
        self.table
            .insert_unique(hash, n, |&i| hasher.hash_one(graph[i]));
        n
    }
}

/// The named children of every element, for looking up path segments: a hash table of
/// element ids hashed by (parent, name), both read from the element itself. Keys that
/// held a copy of the name took 40 bytes a child; an id takes 4 (B1: ~9 MiB at
/// 100,000 modules).
#[derive(Default)]
pub struct Children {
    table: hashbrown::HashTable<ElementId>,
    hasher: hashbrown::DefaultHashBuilder,
}

impl std::fmt::Debug for Children {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Children({} entries)", self.table.len())
    }
}

impl Children {
    fn hash(&self, parent: ElementId, name: &str) -> u64 {
        self.hasher.hash_one((parent, name))
    }

    /// Registers `id` (already in `elements`, with its parent) under its parent. The
    /// caller has made sure the name is not taken.
    pub fn insert(&mut self, elements: &[ElementNode], id: ElementId) {
        let of = |c: &ElementId| {
            let e = &elements[c.0 as usize];
            (e.parent.unwrap_or(ElementId(0)), e.name.as_str())
        };
        let (parent, name) = of(&id);
        let hash = self.hash(parent, name);
        let hasher = &self.hasher;
        self.table
            .insert_unique(hash, id, |c| hasher.hash_one(of(c)));
    }

    /// The child of `parent` called `name`.
    pub fn get(
        &self,
        elements: &[ElementNode],
        parent: ElementId,
        name: &str,
    ) -> Option<ElementId> {
        let hash = self.hash(parent, name);
        self.table
            .find(hash, |c| {
                let e = &elements[c.0 as usize];
                e.parent == Some(parent) && e.name == name
            })
            .copied()
    }

    /// Every registered child, in no particular order.
    pub fn iter(&self) -> impl Iterator<Item = ElementId> + '_ {
        self.table.iter().copied()
    }
}

#[cfg(test)]
mod tests {
    use super::super::*;

    /// The records a large model has hundreds of thousands of keep their size: an
    /// optional setting added inline to one of them costs megabytes at 100,000 modules
    /// (B1); put it behind the record's box of rarely written settings instead.
    #[test]
    fn records_of_large_models_stay_small() {
        assert!(
            std::mem::size_of::<Connection>() <= 168,
            "{}",
            std::mem::size_of::<Connection>()
        );
        assert!(
            std::mem::size_of::<ElementNode>() <= 216,
            "{}",
            std::mem::size_of::<ElementNode>()
        );
        assert!(
            std::mem::size_of::<ModuleInstance>() <= 104,
            "{}",
            std::mem::size_of::<ModuleInstance>()
        );
    }

    fn node(name: &str, parent: Option<ElementId>) -> ElementNode {
        let span =
            ferroc_diagnostics::source::Span::new(ferroc_diagnostics::source::FileId(0), 0, 0);
        ElementNode {
            kind: ElementKind::Group,
            name: name.into(),
            parent,
            name_span: span,
            span,
            instantiated_at: None,
            group_ports: Vec::new(),
            thread: None,
            part: None,
        }
    }

    /// The same name under two parents is two children; a name found under one parent
    /// is not found under another, and the table survives growing (rehashing reads the
    /// keys back from the elements).
    #[test]
    fn children_are_found_by_parent_and_name() {
        let mut elements = vec![node("", None)];
        let mut children = Children::default();
        for i in 0..200u32 {
            elements.push(node(&format!("g{i}"), Some(ElementId(0))));
            children.insert(&elements, ElementId(i + 1));
        }
        let g7 = ElementId(8);
        elements.push(node("g0", Some(g7)));
        children.insert(&elements, ElementId(201));
        assert_eq!(children.get(&elements, ElementId(0), "g7"), Some(g7));
        assert_eq!(
            children.get(&elements, ElementId(0), "g0"),
            Some(ElementId(1))
        );
        assert_eq!(children.get(&elements, g7, "g0"), Some(ElementId(201)));
        assert_eq!(children.get(&elements, g7, "g1"), None);
        assert_eq!(children.get(&elements, ElementId(0), "g200"), None);
        assert_eq!(children.iter().count(), 201);
    }

    #[test]
    fn endpoints_get_one_node_each() {
        let mut graph = DiGraph::new();
        let mut nodes = NodeTable::default();
        let ep = |element: u32, port: u32| Endpoint::Port {
            element: ElementId(element),
            port,
        };
        let first: Vec<_> = (0..300)
            .map(|i| nodes.get_or_add(&mut graph, ep(i, i % 3)))
            .collect();
        let again: Vec<_> = (0..300)
            .map(|i| nodes.get_or_add(&mut graph, ep(i, i % 3)))
            .collect();
        assert_eq!(first, again);
        assert_eq!(graph.node_count(), 300);
        assert_eq!(nodes.get(&graph, &ep(5, 2)), Some(first[5]));
        assert_eq!(nodes.get(&graph, &ep(5, 0)), None);
        let group = Endpoint::GroupPort {
            element: ElementId(5),
            port: 2,
        };
        assert_eq!(nodes.get(&graph, &group), None);
    }
}
