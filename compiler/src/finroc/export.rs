//! `ferroc export finroc` of a ferroc model: the model's first thread container as a
//! FINROC application file. Elements come from the model's top-level modules and groups
//! whose type is a catalogue type (`type="lib.Type"`, or `doc="FINROC: lib/Type: name"`
//! as `import finroc` writes it, which also keeps FINROC's element names), edges from the
//! thread container's `<connect>`s, parameter links from `<param config cmdline>` below.
//! The application's `doc` keeps what the model language cannot say (`defaultname`,
//! `version`, `dependencies`, the root tag), so an imported application exports to the
//! file it came from. What a group builds inside belongs to its C++ constructor or group
//! file and is not written here.

use super::catalogue::{Catalogue, Component};
use super::finstructable::*;
use super::text::{finroc_port_name, ident_of};
use crate::source::Span;
use crate::syntax::Element as Xml;

/// The exported file and what was left out.
pub struct Exported {
    pub doc: Finstructable,
    pub notes: Vec<String>,
}

fn named(text: impl Into<String>, span: Span) -> Named {
    Named {
        text: text.into(),
        span,
    }
}

/// An element of the export: its FINROC name and component type.
struct Top<'a, 'c> {
    xml: &'a Xml,
    name: String,
    component: &'c Component,
}

/// `FINROC: lib/Type: name` → (lib, type, name).
fn parse_doc(doc: &str) -> Option<(&str, &str, &str)> {
    let rest = doc.strip_prefix("FINROC: ")?;
    let (lt, name) = rest.split_once(": ")?;
    let (lib, ty) = lt.split_once('/')?;
    Some((lib, ty, name))
}

fn top<'a, 'c>(e: &'a Xml, catalogue: &'c Catalogue) -> Option<Top<'a, 'c>> {
    let ident = e.value("name")?;
    if let Some((lib, ty, name)) = e.value("doc").and_then(parse_doc) {
        return Some(Top {
            xml: e,
            name: name.to_string(),
            component: catalogue.get(lib, ty)?,
        });
    }
    let (lib, ty) = e.value("type")?.rsplit_once('.')?;
    Some(Top {
        xml: e,
        name: ident.to_string(),
        component: catalogue.get(lib, ty)?,
    })
}

/// Exports the first thread container of a parsed ferroc model.
pub fn export(model: &Xml, catalogue: &Catalogue) -> Result<Exported, String> {
    if model.name != "application" {
        return Err(format!(
            "<{}> is not a ferroc application model",
            model.name
        ));
    }
    let mut notes = Vec::new();
    let facts: Vec<(&str, &str)> = model
        .value("doc")
        .unwrap_or_default()
        .split("; ")
        .filter_map(|f| f.split_once(": "))
        .collect();
    let fact = |k: &str| facts.iter().find(|(key, _)| *key == k).map(|(_, v)| *v);
    let parts: Vec<&Xml> = model.children_named("part").collect();
    let threads: Vec<&Xml> = parts
        .iter()
        .flat_map(|p| p.children_named("thread"))
        .collect();
    let thread = *threads
        .first()
        .ok_or("the model has no thread container to export")?;
    if threads.len() > 1 {
        notes.push("only the first thread container is exported (a .finroc file is one)".into());
    }
    let span = model.name_span;
    let version = fact("version").and_then(|v| v.parse().ok());
    let mut tops = Vec::new();
    for c in thread
        .children
        .iter()
        .filter(|c| c.name == "module" || c.name == "group")
    {
        match top(c, catalogue) {
            Some(t) => tops.push(t),
            None => notes.push(format!(
                "`{}`: its type is not a FINROC catalogue type",
                c.value("name").unwrap_or_default()
            )),
        }
    }
    let mut dependencies: Vec<String> = Vec::new();
    match fact("dependencies") {
        Some(d) => dependencies.extend(d.split(", ").map(str::to_string)),
        None => {
            for t in &tops {
                if !dependencies.contains(&t.component.library) {
                    dependencies.push(t.component.library.clone());
                }
            }
        }
    }
    let elements = tops
        .iter()
        .map(|t| Element {
            name: named(&t.name, t.xml.span),
            group: Some(named(&t.component.library, t.xml.span)),
            ty: Some(named(&t.component.name, t.xml.span)),
            span: t.xml.span,
            constructor: Vec::new(),
            parameters: Some(Vec::new()),
            children: Vec::new(),
        })
        .collect();
    let mut edges = Vec::new();
    for c in thread.children_named("connect") {
        let (Some(from), Some(to)) = (c.value("from"), c.value("to")) else {
            continue;
        };
        match (end(from, &tops, c.span), end(to, &tops, c.span)) {
            (Some(src), Some(dest)) => edges.push(Edge {
                src,
                dest,
                flags: Vec::new(),
                conversion: None,
                params: Vec::new(),
                span: c.span,
            }),
            _ => notes.push(format!(
                "connect {from} -> {to}: an end is not a port of an exported element"
            )),
        }
    }
    let mut links = Vec::new();
    for t in &tops {
        collect_links(
            t.xml,
            vec![t.name.clone()],
            Some(t.component),
            catalogue,
            version.is_none(),
            &mut links,
        );
    }
    Ok(Exported {
        doc: Finstructable {
            file: span.file,
            root_tag: fact("root").unwrap_or("Finstructable").to_string(),
            root_span: span,
            version,
            defaultname: fact("defaultname").map(|d| named(d, span)),
            has_dependencies: !dependencies.is_empty(),
            dependencies: dependencies.into_iter().map(|d| named(d, span)).collect(),
            interfaces: Vec::new(),
            elements,
            edges,
            links,
        },
        notes,
    })
}

/// `simulation/pose` → `Simulation/Sensor Output/Pose`.
fn end(path: &str, tops: &[Top<'_, '_>], span: Span) -> Option<EdgeEnd> {
    let (first, port) = path.split_once('/')?;
    let t = tops.iter().find(|t| t.xml.value("name") == Some(first))?;
    let p = t
        .component
        .ports
        .iter()
        .find(|p| ident_of(&p.name) == port)?;
    let segments = vec![t.name.clone(), p.interface.clone(), p.name.clone()];
    Some(EdgeEnd {
        raw: named(segments.join("/"), span),
        scheme: None,
        absolute: false,
        segments,
    })
}

/// Parameter links of `<param config>` at and below `e` (FINROC names on the way).
fn collect_links(
    e: &Xml,
    path: Vec<String>,
    component: Option<&Component>,
    catalogue: &Catalogue,
    legacy: bool,
    out: &mut Vec<ParamLink>,
) {
    for p in e.children_named("param") {
        let Some(config) = p.value("config") else {
            continue;
        };
        let entry = config.split_once('#').map_or(config, |(_, e)| e);
        let ident = p.value("name").unwrap_or_default();
        let name = component
            .and_then(|c| c.params.iter().find(|(n, _)| ident_of(n) == ident))
            .map(|(n, _)| n.clone())
            .unwrap_or_else(|| finroc_port_name(ident));
        let mut full = path.clone();
        if legacy {
            full.push("Parameters".into());
        }
        full.push(name);
        out.push(ParamLink {
            path: full,
            path_span: p.span,
            config: Some(named(entry, p.span)),
            cmdline: p.value("cmdline").map(|c| named(c, p.span)),
            default: None,
            legacy,
            span: p.span,
        });
    }
    for c in e
        .children
        .iter()
        .filter(|c| c.name == "module" || c.name == "group")
    {
        let t = top(c, catalogue);
        let name = t.as_ref().map_or_else(
            || c.value("name").unwrap_or_default().to_string(),
            |t| t.name.clone(),
        );
        let mut next = path.clone();
        next.push(name);
        collect_links(c, next, t.map(|t| t.component), catalogue, legacy, out);
    }
}
