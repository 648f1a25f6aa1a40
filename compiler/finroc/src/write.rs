//! Writes a [`Finstructable`] as FINROC's `tFinstructable::SaveXml` does (17.03): two
//! spaces per level, attributes in FINROC's order, text escaped by `ferroc_syntax::escape`,
//! version-1703 edge paths percent-encoded, `<parameter_links>` children sorted by name
//! with parameters first. A file FINROC wrote and nobody changed comes back byte for
//! byte (FINROC's own runtime_construction test checks the same of its writer).
//! Comments and unknown tags are not kept, as FINROC does not keep them.

use super::finstructable::*;
use super::text::percent_encode;
use ferroc_syntax::escape;
use std::collections::BTreeMap;

/// `name="value"` pairs.
fn attrs(list: &[(&str, String)]) -> String {
    list.iter()
        .map(|(n, v)| format!(" {n}=\"{}\"", escape::attr(v)))
        .collect()
}

/// Writes `doc` as a FINROC file.
pub fn write(doc: &Finstructable) -> String {
    let mut o = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let mut root = Vec::new();
    if let Some(d) = &doc.defaultname {
        root.push(("defaultname", d.text.clone()));
    }
    if let Some(v) = doc.version {
        root.push(("version", v.to_string()));
    }
    if doc.has_dependencies {
        let deps: Vec<&str> = doc.dependencies.iter().map(|d| d.text.as_str()).collect();
        root.push(("dependencies", deps.join(", ")));
    }
    let empty = doc.interfaces.is_empty()
        && doc.elements.is_empty()
        && doc.edges.is_empty()
        && doc.links.is_empty();
    if empty {
        o.push_str(&format!("<{}{}/>\n", doc.root_tag, attrs(&root)));
        return o;
    }
    o.push_str(&format!("<{}{}>\n", doc.root_tag, attrs(&root)));
    for i in &doc.interfaces {
        if i.ports.is_empty() {
            o.push_str(&format!(
                "  <interface{}/>\n",
                attrs(&[("name", i.name.text.clone())])
            ));
            continue;
        }
        o.push_str(&format!(
            "  <interface{}>\n",
            attrs(&[("name", i.name.text.clone())])
        ));
        for p in &i.ports {
            let mut a = vec![("name", p.name.text.clone())];
            if let Some(t) = &p.ty {
                a.push(("type", t.text.clone()));
            }
            if p.output {
                a.push(("output", "true".into()));
            }
            if p.shared {
                a.push(("shared", "true".into()));
            }
            o.push_str(&format!("    <port{}/>\n", attrs(&a)));
        }
        o.push_str("  </interface>\n");
    }
    for e in &doc.elements {
        element(e, 1, &mut o);
    }
    for e in &doc.edges {
        edge(e, doc.version.is_some(), &mut o);
    }
    for l in doc.links.iter().filter(|l| l.legacy) {
        let mut a = vec![("link", l.path.join("/"))];
        for (n, v) in [
            ("config", &l.config),
            ("cmdline", &l.cmdline),
            ("default", &l.default),
        ] {
            if let Some(v) = v {
                a.push((n, v.text.clone()));
            }
        }
        o.push_str(&format!("  <parameter{}/>\n", attrs(&a)));
    }
    let tree: Vec<&ParamLink> = doc.links.iter().filter(|l| !l.legacy).collect();
    if !tree.is_empty() {
        o.push_str("  <parameter_links>\n");
        link_tree(&tree, 0, 2, &mut o);
        o.push_str("  </parameter_links>\n");
    }
    o.push_str(&format!("</{}>\n", doc.root_tag));
    o
}

fn pad(level: usize) -> String {
    "  ".repeat(level)
}

fn params(tag: &str, list: &[StaticParam], level: usize, o: &mut String) {
    if list.is_empty() {
        o.push_str(&format!("{}<{tag}/>\n", pad(level)));
        return;
    }
    o.push_str(&format!("{}<{tag}>\n", pad(level)));
    for p in list {
        let mut a = vec![("name", p.name.text.clone())];
        a.extend(p.attrs.iter().map(|(n, v)| (n.as_str(), v.text.clone())));
        if p.value.text.is_empty() {
            o.push_str(&format!("{}<parameter{}/>\n", pad(level + 1), attrs(&a)));
        } else {
            o.push_str(&format!(
                "{}<parameter{}>{}</parameter>\n",
                pad(level + 1),
                attrs(&a),
                escape::content(&p.value.text)
            ));
        }
    }
    o.push_str(&format!("{}</{tag}>\n", pad(level)));
}

fn element(e: &Element, level: usize, o: &mut String) {
    let mut a = vec![("name", e.name.text.clone())];
    if let Some(g) = &e.group {
        a.push(("group", g.text.clone()));
    }
    if let Some(t) = &e.ty {
        a.push(("type", t.text.clone()));
    }
    if e.constructor.is_empty() && e.parameters.is_none() && e.children.is_empty() {
        o.push_str(&format!("{}<element{}/>\n", pad(level), attrs(&a)));
        return;
    }
    o.push_str(&format!("{}<element{}>\n", pad(level), attrs(&a)));
    if !e.constructor.is_empty() {
        params("constructor", &e.constructor, level + 1, o);
    }
    if let Some(p) = &e.parameters {
        params("parameters", p, level + 1, o);
    }
    for c in &e.children {
        element(c, level + 1, o);
    }
    o.push_str(&format!("{}</element>\n", pad(level)));
}

fn end(e: &EdgeEnd, encoded: bool) -> String {
    if !encoded {
        return e.raw.text.clone();
    }
    let path: Vec<String> = e.segments.iter().map(|s| percent_encode(s)).collect();
    format!(
        "{}{}{}",
        e.scheme
            .as_ref()
            .map(|s| format!("{s}:"))
            .unwrap_or_default(),
        if e.absolute { "/" } else { "" },
        path.join("/")
    )
}

fn edge(e: &Edge, encoded: bool, o: &mut String) {
    let mut a = vec![
        ("src", end(&e.src, encoded)),
        ("dest", end(&e.dest, encoded)),
    ];
    if !e.flags.is_empty() {
        let names: Vec<String> = e
            .flags
            .iter()
            .filter_map(|f| FLAGS.iter().find(|(x, _, _)| x == f))
            .map(|(_, n, i)| format!("{n} ({i})"))
            .collect();
        a.push(("flags", names.join(", ")));
    }
    if e.conversion.is_none() && e.params.is_empty() {
        o.push_str(&format!("  <edge{}/>\n", attrs(&a)));
        return;
    }
    o.push_str(&format!("  <edge{}>\n", attrs(&a)));
    if let Some(c) = &e.conversion {
        let ca: Vec<(&str, String)> = c
            .attrs
            .iter()
            .map(|(n, v)| (n.as_str(), v.text.clone()))
            .collect();
        o.push_str(&format!("    <conversion{}/>\n", attrs(&ca)));
    }
    for (n, v) in &e.params {
        o.push_str(&format!(
            "    <parameter{}>{}</parameter>\n",
            attrs(&[("name", n.text.clone())]),
            escape::content(&v.text)
        ));
    }
    o.push_str("  </edge>\n");
}

/// `<parameter_links>`: parameters of this level first, then child elements by name.
fn link_tree(links: &[&ParamLink], depth: usize, level: usize, o: &mut String) {
    let mut children: BTreeMap<&str, Vec<&ParamLink>> = BTreeMap::new();
    for l in links {
        if l.path.len() == depth + 1 {
            let mut a = vec![("name", l.path[depth].clone())];
            for (n, v) in [
                ("config", &l.config),
                ("cmdline", &l.cmdline),
                ("default", &l.default),
            ] {
                if let Some(v) = v {
                    a.push((n, v.text.clone()));
                }
            }
            o.push_str(&format!("{}<parameter{}/>\n", pad(level), attrs(&a)));
        } else if l.path.len() > depth + 1 {
            children.entry(l.path[depth].as_str()).or_default().push(l);
        }
    }
    for (name, list) in children {
        o.push_str(&format!(
            "{}<element{}>\n",
            pad(level),
            attrs(&[("name", name.to_string())])
        ));
        link_tree(&list, depth + 1, level + 1, o);
        o.push_str(&format!("{}</element>\n", pad(level)));
    }
}
