//! `ferroc import finroc`: a FINROC application as a ferroc model.
//!
//! The `.finroc` file is one thread container (finroc_run's, 40 ms by default). Each
//! element whose type the catalogue knows becomes a `<module>` (type from the
//! catalogue's manifest) or, for a composite, a `<group>` holding what its C++
//! constructor builds (catalogue) and what its group file adds (checkout), with the
//! group's ports; edges become `<connect>`s, parameter links `<param config cmdline>`.
//! What cannot be imported (types not in the catalogue, URI edges, static parameters)
//! is left out with a comment at its place and a line in the returned notes.

use super::catalogue::{Catalogue, Component};
use super::checkout::Checkout;
use super::finstructable::{Edge, Element, Finstructable};
use super::text::ident_of;
use ferroc_syntax::escape;
use std::collections::{BTreeSet, HashMap, HashSet};
use std::fmt::Write;

/// The imported model.
pub struct Imported {
    pub model: String,
    /// Catalogue libraries the model uses (their manifests go beside the model).
    pub libraries: BTreeSet<String>,
    /// What was left out, one sentence each.
    pub notes: Vec<String>,
}

enum Kind<'c> {
    Module(&'c Component),
    Group(&'c Component),
}

struct Node<'c> {
    finroc: String,
    name: String,
    kind: Kind<'c>,
    children: Vec<Node<'c>>,
    connects: Vec<(String, String)>,
    params: Vec<(String, String, Option<String>)>,
    comments: Vec<String>,
    /// Edges read but not yet turned into connects (all elements must be known first).
    pending: Vec<Edge>,
    /// Each child's FINROC name to the first child of that name, and the ferroc names
    /// taken with the next suffix to try for each base name: an application of 100,000
    /// elements is imported in linear time.
    index: ChildIndex,
}

#[derive(Default)]
struct ChildIndex {
    by_finroc: HashMap<String, usize>,
    taken: HashSet<String>,
    next_suffix: HashMap<String, usize>,
}

impl<'c> Node<'c> {
    fn new(finroc: String, name: String, kind: Kind<'c>) -> Self {
        Node {
            finroc,
            name,
            kind,
            children: Vec::new(),
            connects: Vec::new(),
            params: Vec::new(),
            comments: Vec::new(),
            pending: Vec::new(),
            index: ChildIndex::default(),
        }
    }

    /// `name`, or `name_2`, `name_3`, … : the first no child has.
    fn unique(&mut self, name: String) -> String {
        let index = &mut self.index;
        if !index.taken.contains(&name) {
            return name;
        }
        // Suffixes below the one remembered are taken: names are only ever added.
        let mut i = index.next_suffix.get(&name).copied().unwrap_or(2);
        let mut candidate = format!("{name}_{i}");
        while index.taken.contains(&candidate) {
            i += 1;
            candidate = format!("{name}_{i}");
        }
        index.next_suffix.insert(name, i + 1);
        candidate
    }

    fn push_child(&mut self, child: Node<'c>) {
        let i = self.children.len();
        self.index
            .by_finroc
            .entry(child.finroc.clone())
            .or_insert(i);
        self.index.taken.insert(child.name.clone());
        self.children.push(child);
    }

    /// The first child of FINROC name `finroc`.
    fn child(&self, finroc: &str) -> Option<&Node<'c>> {
        self.index.by_finroc.get(finroc).map(|&i| &self.children[i])
    }

    fn child_mut(&mut self, finroc: &str) -> Option<&mut Node<'c>> {
        let i = *self.index.by_finroc.get(finroc)?;
        Some(&mut self.children[i])
    }
}

struct Ctx<'a> {
    catalogue: &'a Catalogue,
    checkout: &'a Checkout,
    /// How a config file is named from the model (its path relative to the model).
    config_ref: &'a dyn Fn(&super::config::ConfigFile) -> String,
    libraries: BTreeSet<String>,
    notes: Vec<String>,
}

/// Imports `doc` (a `.finroc` application).
pub fn import(
    doc: &Finstructable,
    name: &str,
    catalogue: &Catalogue,
    checkout: &Checkout,
    config_ref: &dyn Fn(&super::config::ConfigFile) -> String,
) -> Imported {
    let mut ctx = Ctx {
        catalogue,
        checkout,
        config_ref,
        libraries: BTreeSet::new(),
        notes: Vec::new(),
    };
    let mut root = root_node(catalogue);
    fill(&mut ctx, &mut root, &doc.elements, &doc.edges);
    connect(&mut ctx, &mut root);
    if !doc.interfaces.is_empty() {
        ctx.notes.push(
            "the application's own interfaces (ports for other processes) are not imported".into(),
        );
    }
    for link in &doc.links {
        attach_link(&mut ctx, &mut root, link);
    }
    let model = write_model(&ident_of(name), &file_facts(doc), &ctx.libraries, &root);
    Imported {
        model,
        libraries: ctx.libraries,
        notes: ctx.notes,
    }
}

/// The application's node: `finroc_run`'s thread container.
fn root_node(catalogue: &Catalogue) -> Node<'_> {
    Node::new(
        String::new(),
        "main".into(),
        Kind::Group(
            catalogue
                .get(
                    "finroc_plugins_structure",
                    "ThreadContainer<SenseControlGroup>",
                )
                .expect("built-in"),
        ),
    )
}

/// What the model cannot say but `export finroc` needs, for `doc` (see export.rs).
fn file_facts(doc: &Finstructable) -> Vec<String> {
    let mut facts = vec!["FINROC application".to_string()];
    if doc.root_tag != "Finstructable" {
        facts.push(format!("root: {}", doc.root_tag));
    }
    if let Some(d) = &doc.defaultname {
        facts.push(format!("defaultname: {}", d.text));
    }
    if let Some(v) = doc.version {
        facts.push(format!("version: {v}"));
    }
    if doc.has_dependencies {
        let deps: Vec<&str> = doc.dependencies.iter().map(|d| d.text.as_str()).collect();
        facts.push(format!("dependencies: {}", deps.join(", ")));
    }
    facts
}

/// The model text: the application `app` with its facts, the libraries it uses, and
/// one part and thread container holding the imported tree.
fn write_model(
    app: &str,
    facts: &[String],
    libraries: &BTreeSet<String>,
    root: &Node<'_>,
) -> String {
    let mut o = String::new();
    let _ = writeln!(o, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>");
    let _ = writeln!(
        o,
        "<!-- Imported from FINROC by `ferroc import finroc`. -->"
    );
    let _ = writeln!(
        o,
        "<application name=\"{app}\" version=\"1\" profile=\"finroc\" doc=\"{}\">",
        escape::attr(&facts.join("; "))
    );
    for lib in libraries {
        let _ = writeln!(o, "  <use library=\"{lib}\" manifest=\"{lib}.lib.xml\"/>");
    }
    let _ = writeln!(o, "  <part name=\"{app}\" host=\"localhost\">");
    let _ = writeln!(
        o,
        "    <!-- finroc_run's thread container: 40 ms unless started with -t -->"
    );
    let _ = writeln!(o, "    <thread name=\"main\" period=\"40ms\">");
    body(root, 3, &mut o);
    let _ = writeln!(o, "    </thread>");
    let _ = writeln!(o, "  </part>");
    let _ = writeln!(o, "</application>");
    o
}

/// Adds `elements` and `edges` (of a file or of a constructor) to `node`.
fn fill<'c>(ctx: &mut Ctx<'c>, node: &mut Node<'c>, elements: &[Element], edges: &[Edge]) {
    for e in elements {
        let (Some(lib), Some(ty)) = (&e.group, &e.ty) else {
            continue;
        };
        let Some(component) = ctx.catalogue.get(&lib.text, &ty.text) else {
            node.comments.push(format!(
                "not imported: `{}` ({} in {}) is not in the catalogue",
                e.name.text, ty.text, lib.text
            ));
            ctx.notes.push(format!(
                "`{}`: type `{}` in `{}` is not in the catalogue",
                e.name.text, ty.text, lib.text
            ));
            continue;
        };
        let name = node.unique(ident_of(&e.name.text));
        let kind = if component.composite {
            Kind::Group(component)
        } else {
            Kind::Module(component)
        };
        let mut child = Node::new(e.name.text.clone(), name, kind);
        if component.composite {
            if let Some(content) = &component.content {
                fill(ctx, &mut child, &content.elements, &content.edges);
            }
            let file = e
                .xml_file()
                .map(|p| p.value.text.trim().to_string())
                .or_else(|| component.xml_file.clone());
            let checkout: &'c Checkout = ctx.checkout;
            match file.as_deref().and_then(|f| checkout.group_file(f)) {
                Some(g) => fill(ctx, &mut child, &g.doc.elements, &g.doc.edges),
                None => {
                    if let Some(f) = file {
                        ctx.notes.push(format!("`{}`: its group file {f} is not in the checkout; only what its constructor builds is imported", e.name.text));
                    }
                }
            }
        } else {
            ctx.libraries.insert(component.library.clone());
        }
        if !e.children.is_empty() {
            fill(ctx, &mut child, &e.children, &[]);
        }
        connect(ctx, &mut child);
        node.push_child(child);
    }
    node.pending.extend(edges.iter().cloned());
}

/// Turns a node's pending edges into connects, now that its elements are known.
fn connect(ctx: &mut Ctx<'_>, node: &mut Node<'_>) {
    for edge in std::mem::take(&mut node.pending) {
        match (
            path_of(node, &edge.src.segments),
            path_of(node, &edge.dest.segments),
        ) {
            (Some(a), Some(b)) if edge.src.scheme.is_none() && edge.dest.scheme.is_none() => {
                node.connects.push((a, b))
            }
            _ => {
                node.comments.push(format!(
                    "not imported: edge {} -> {}",
                    edge.src.path(),
                    edge.dest.path()
                ));
                ctx.notes.push(format!(
                    "edge `{}` → `{}`: an end is not imported",
                    edge.src.path(),
                    edge.dest.path()
                ));
            }
        }
    }
}

/// A FINROC path (relative to `node`) as a ferroc path: `Element/Interface/Port` →
/// `element/port`; `Interface/Port` of the node itself → `port`.
fn path_of(node: &Node<'_>, segs: &[String]) -> Option<String> {
    if segs.len() == 2 {
        let (Kind::Group(c) | Kind::Module(c)) = node.kind;
        if c.interfaces.iter().any(|i| i == &segs[0]) && node.child(&segs[0]).is_none() {
            return Some(
                c.port(&segs[0], &segs[1])
                    .map_or_else(|| ident_of(&segs[1]), |p| p.member.clone()),
            );
        }
    }
    let child = node.child(&segs[0])?;
    let rest = path_of(child, &segs[1..])?;
    Some(format!("{}/{rest}", child.name))
}

fn attach_link(ctx: &mut Ctx<'_>, root: &mut Node<'_>, link: &super::finstructable::ParamLink) {
    let Some((param, elems)) = link.path.split_last() else {
        return;
    };
    let mut node = &mut *root;
    for seg in elems.iter().filter(|s| *s != "Parameters") {
        match node.child_mut(seg) {
            Some(n) => node = n,
            None => {
                ctx.notes.push(format!(
                    "parameter link `{}`: `{seg}` is not imported",
                    link.path.join("/")
                ));
                return;
            }
        }
    }
    let config = link.config.as_ref().and_then(|c| {
        let (file, _) = ctx.checkout.config_entry(&c.text)?;
        Some(format!("{}#{}", (ctx.config_ref)(file), c.text))
    });
    if link.config.is_some() && config.is_none() {
        ctx.notes.push(format!(
            "parameter link `{}`: its config entry is in no config file of the checkout",
            link.path.join("/")
        ));
    }
    if let Some(config) = config {
        node.params.push((
            ident_of(param),
            config,
            link.cmdline.as_ref().map(|c| c.text.clone()),
        ));
    }
}

fn body(node: &Node<'_>, level: usize, o: &mut String) {
    let pad = "  ".repeat(level);
    if let Kind::Group(c) = node.kind {
        if level > 3 {
            for p in &c.ports {
                let ty = ports_type(c, p);
                let unit = p
                    .unit
                    .as_ref()
                    .map(|u| format!(" unit=\"{u}\""))
                    .unwrap_or_default();
                let dir = if p.output { "out" } else { "in" };
                let _ = writeln!(
                    o,
                    "{pad}<port name=\"{}\" dir=\"{dir}\" type=\"{ty}\"{unit}/>",
                    p.member
                );
            }
        }
    }
    for c in &node.comments {
        let _ = writeln!(o, "{pad}<!-- {} -->", escape::text(c).replace("--", "- -"));
    }
    for child in &node.children {
        match child.kind {
            Kind::Module(c) => {
                let _ = write!(
                    o,
                    "{pad}<module name=\"{}\" type=\"{}.{}\" doc=\"{}\"",
                    child.name,
                    c.library,
                    c.name,
                    finroc_doc(c, &child.finroc)
                );
                if child.params.is_empty() {
                    let _ = writeln!(o, "/>");
                } else {
                    let _ = writeln!(o, ">");
                    for (name, config, cmdline) in &child.params {
                        let cmd = cmdline
                            .as_ref()
                            .map(|c| format!(" cmdline=\"{}\"", escape::attr(c)))
                            .unwrap_or_default();
                        let _ = writeln!(
                            o,
                            "{pad}  <param name=\"{name}\" config=\"{}\"{cmd}/>",
                            escape::attr(config)
                        );
                    }
                    let _ = writeln!(o, "{pad}</module>");
                }
            }
            Kind::Group(c) => {
                let _ = writeln!(
                    o,
                    "{pad}<group name=\"{}\" doc=\"{}\">",
                    child.name,
                    finroc_doc(c, &child.finroc)
                );
                body(child, level + 1, o);
                let _ = writeln!(o, "{pad}</group>");
            }
        }
    }
    for (a, b) in &node.connects {
        let _ = writeln!(o, "{pad}<connect from=\"{a}\" to=\"{b}\"/>");
    }
}

/// `FINROC: library/type: element name`, which `export finroc` reads back.
pub fn finroc_doc(c: &Component, name: &str) -> String {
    escape::attr(&format!("FINROC: {}/{}: {name}", c.library, c.name)).into_owned()
}

fn ports_type(_c: &Component, p: &super::catalogue::Port) -> String {
    super::catalogue::builtin()
        .ferroc_types
        .get(&p.ty)
        .cloned()
        .unwrap_or_else(|| p.ty.clone())
}

#[cfg(test)]
mod tests {
    use super::*;
    use ferroc_diagnostics::diagnostic::Diagnostics;
    use ferroc_diagnostics::source::FileId;

    /// Issue 27 item 14: each element's name was made unique by scanning every earlier
    /// child, and every suffix again from `_2` (an application of many elements of one
    /// name did not finish); names and edge ends are now found through an index. The
    /// elements of one name get the suffixes in order, and an edge between the last two
    /// finds them.
    #[test]
    fn many_elements_of_one_name_are_imported_in_order() {
        const N: usize = 20_000;
        let mut text = String::from("<Finstructable version=\"1703\">");
        for _ in 0..N {
            text.push_str(
                "<element name=\"Noise\" group=\"finroc_projects_crash_course\" type=\"AddNoise\"/>",
            );
        }
        text.push_str(
            "<element name=\"Last\" group=\"finroc_projects_crash_course\" type=\"AddNoise\"/>",
        );
        text.push_str("<edge src=\"Noise/Output/Output\" dest=\"Last/Input/Input\"/>");
        text.push_str("</Finstructable>");
        let root = ferroc_syntax::xml::parse(FileId(0), &text, 64).unwrap();
        let doc = crate::read::read(FileId(0), &root, &mut Diagnostics::default());
        let checkout = Checkout::default();
        let imported = import(
            &doc,
            "many",
            crate::catalogue::builtin(),
            &checkout,
            &|_| String::new(),
        );
        let model = &imported.model;
        assert!(
            model.contains("<module name=\"noise\" "),
            "the first keeps its name"
        );
        assert!(model.contains("<module name=\"noise_2\" "));
        assert!(model.contains(&format!("<module name=\"noise_{N}\" ")));
        assert!(!model.contains(&format!("<module name=\"noise_{}\" ", N + 1)));
        // The edge leads from the first element of the name, as FINROC resolves it.
        assert!(
            model.contains("<connect from=\"noise/output\" to=\"last/input\"/>"),
            "{}",
            &model[model.len().saturating_sub(600)..]
        );
    }
}
