//! Queries on the resolved application: nodes, ports, connections and elements by
//! endpoint, name or kind (what the passes and the back ends look things up with).

use super::*;

impl Application {
    /// The graph node of a connected endpoint.
    pub fn node(&self, endpoint: Endpoint) -> Option<NodeIndex> {
        self.nodes.get(&self.graph, &endpoint)
    }

    /// The child of `parent` called `name`.
    pub fn child(&self, parent: ElementId, name: &str) -> Option<ElementId> {
        self.children.get(&self.elements, parent, name)
    }

    /// The names of `parent`'s children (for "did you mean"; not on a hot path).
    pub fn child_names(&self, parent: ElementId) -> impl Iterator<Item = &str> + '_ {
        self.children
            .iter()
            .map(move |c| self.element(c))
            .filter(move |e| e.parent == Some(parent))
            .map(|e| e.name.as_str())
    }

    pub fn element(&self, id: ElementId) -> &ElementNode {
        &self.elements[id.0 as usize]
    }

    /// `robot/control/laser` for messages.
    pub fn path(&self, id: ElementId) -> String {
        let mut names = Vec::new();
        let mut cur = Some(id);
        while let Some(c) = cur {
            let e = self.element(c);
            if e.parent.is_none() {
                break;
            }
            names.push(e.name.as_str());
            cur = e.parent;
        }
        names.reverse();
        names.join("/")
    }

    pub fn module_type<'l>(&self, libs: &'l LibrarySet, id: ElementId) -> Option<&'l ModuleType> {
        match &self.element(id).kind {
            ElementKind::Module(m) => Some(&libs.get(m.library).module_types[m.type_index]),
            _ => None,
        }
    }

    /// All ports of a module instance: its type's, then the instance's own.
    pub fn module_ports<'a>(
        &'a self,
        libs: &'a LibrarySet,
        id: ElementId,
    ) -> impl Iterator<Item = (u32, &'a PortDecl)> + 'a {
        let (type_ports, extra): (&[PortDecl], &[PortDecl]) = match &self.element(id).kind {
            ElementKind::Module(m) => (
                &libs.get(m.library).module_types[m.type_index].ports,
                &m.extra_ports,
            ),
            _ => (&[], &[]),
        };
        type_ports
            .iter()
            .chain(extra.iter())
            .enumerate()
            .map(|(i, p)| (i as u32, p))
    }

    /// The port or parameter behind an endpoint, with its type resolved.
    pub fn view<'a>(&'a self, libs: &'a LibrarySet, endpoint: Endpoint) -> Option<PortView<'a>> {
        match endpoint {
            Endpoint::Port { element, port } => {
                let ElementKind::Module(m) = &self.element(element).kind else {
                    return None;
                };
                // Direct indexing: the type's ports first, then the instance's own.
                let type_ports = &libs.get(m.library).module_types[m.type_index].ports;
                let port = port as usize;
                let decl = match type_ports.get(port) {
                    Some(d) => d,
                    None => m.extra_ports.get(port - type_ports.len())?,
                };
                let (ty, unit) = match &decl.ty {
                    // A port its type leaves without a unit may get one from the instance.
                    PortType::Fixed(t) => {
                        (t, decl.unit.as_ref().or_else(|| m.port_unit(port as u32)))
                    }
                    PortType::SameAs(group) => {
                        let (_, t, u) = m.flexible_types.iter().find(|(g, _, _)| g == group)?;
                        (t, decl.unit.as_ref().or(u.as_ref()))
                    }
                };
                Some(PortView {
                    name: &decl.name,
                    ty,
                    unit,
                    span: decl.span,
                    required: decl.required,
                    merge: decl.merge,
                    role: decl.role,
                    dir: decl.dir,
                })
            }
            Endpoint::GroupPort { element, port } => {
                let p = self.element(element).group_ports.get(port as usize)?;
                Some(PortView::plain(
                    &p.name,
                    &p.ty,
                    p.unit.as_ref(),
                    p.span,
                    p.dir,
                ))
            }
            Endpoint::Param { element, param } => {
                let mt = self.module_type(libs, element)?;
                let p = mt.params.get(param as usize)?;
                Some(PortView::plain(
                    &p.name,
                    &p.ty,
                    p.unit.as_ref(),
                    p.span,
                    PortDir::In,
                ))
            }
        }
    }

    /// Connections into an endpoint.
    pub fn incoming(&self, endpoint: Endpoint) -> impl Iterator<Item = &Connection> + '_ {
        self.node(endpoint)
            .into_iter()
            .flat_map(move |n| self.graph.edges_directed(n, petgraph::Direction::Incoming))
            .map(move |e| &self.connections[*e.weight()])
    }

    pub fn has_outgoing(&self, endpoint: Endpoint) -> bool {
        self.node(endpoint).is_some_and(|n| {
            self.graph
                .edges_directed(n, petgraph::Direction::Outgoing)
                .next()
                .is_some()
        })
    }

    /// The nearest group above an element (threads between them do not count), if any.
    pub fn enclosing_group(&self, id: ElementId) -> Option<ElementId> {
        let mut cur = self.element(id).parent;
        while let Some(c) = cur {
            match self.element(c).kind {
                ElementKind::Group => return Some(c),
                ElementKind::Thread { .. } => cur = self.element(c).parent,
                _ => return None,
            }
        }
        None
    }

    /// Whether `ancestor` is `id` or one of its ancestors.
    pub fn contains(&self, ancestor: ElementId, id: ElementId) -> bool {
        let mut cur = Some(id);
        while let Some(c) = cur {
            if c == ancestor {
                return true;
            }
            cur = self.element(c).parent;
        }
        false
    }

    pub fn modules(&self) -> impl Iterator<Item = (ElementId, &ModuleInstance)> {
        self.elements
            .iter()
            .enumerate()
            .filter_map(|(i, e)| match &e.kind {
                ElementKind::Module(m) => Some((ElementId(i as u32), m)),
                _ => None,
            })
    }
}

impl<'a> PortView<'a> {
    /// An endpoint that is neither required nor merging and has no iB2C role: a group
    /// port or a parameter.
    fn plain(
        name: &'a str,
        ty: &'a Type,
        unit: Option<&'a Unit>,
        span: Span,
        dir: PortDir,
    ) -> Self {
        PortView {
            name,
            ty,
            unit,
            span,
            required: false,
            merge: false,
            role: PortRole::Plain,
            dir,
        }
    }
}
