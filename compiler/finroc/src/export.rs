//! `ferroc export finroc` of a ferroc model: each thread container as a FINROC
//! application file. Elements come from the model's top-level modules and groups
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
use ferroc_diagnostics::source::Span;
use ferroc_syntax::Element as Xml;

/// The exported file and what was left out.
pub struct Exported {
    /// The ferroc name of the thread container it came from.
    pub container: String,
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

/// Exports each thread container of a parsed ferroc model as one FINROC application
/// (finroc_run makes one top-level thread container per `.finroc` file it is given).
/// The file facts `import finroc` kept in the application's `doc` (`version`, the root
/// tag) hold for every file; `defaultname` and `dependencies` for the first; the others
/// are named after their thread container and depend on what they use.
/// A `<connect>` between two containers is left out with a note: in FINROC it is an
/// edge between two files' containers, which neither file can say relative to itself.
pub fn export(model: &Xml, catalogue: &Catalogue) -> Result<Vec<Exported>, String> {
    if model.name != "application" {
        return Err(format!(
            "<{}> is not a ferroc application model",
            model.name
        ));
    }
    let threads: Vec<(&Xml, &Xml)> = model
        .children_named("part")
        .flat_map(|p| p.children_named("thread").map(move |t| (p, t)))
        .collect();
    if threads.is_empty() {
        return Err("the model has no thread container to export".into());
    }
    let mut out = Vec::new();
    for (i, (part, thread)) in threads.iter().enumerate() {
        let mut exported = export_thread(model, part, thread, catalogue, i == 0)?;
        if threads.len() > 1 {
            for (c, at_model) in outer_connects(model, part) {
                let inside = |p: Option<&str>| {
                    p.is_some_and(|p| thread_local(p, at_model, part, thread).is_some())
                };
                let (from, to) = (c.value("from"), c.value("to"));
                if inside(from) && !inside(to) {
                    exported.notes.push(format!(
                        "connect {} -> {}: it joins two thread containers (two .finroc files)",
                        from.unwrap_or_default(),
                        to.unwrap_or_default()
                    ));
                }
            }
        }
        out.push(exported);
    }
    Ok(out)
}

/// `path` of a `<connect>` at the application level (`part/thread/…`, `at_model`) or
/// in `part` (`thread/…`) as a path inside `thread`, if it leads there.
fn thread_local<'p>(path: &'p str, at_model: bool, part: &Xml, thread: &Xml) -> Option<&'p str> {
    let in_part = if at_model {
        path.strip_prefix(part.value("name")?)?.strip_prefix('/')?
    } else {
        path
    };
    in_part
        .strip_prefix(thread.value("name")?)?
        .strip_prefix('/')
}

/// The `<connect>`s of the application and of `part`, with whether each is the
/// application's.
fn outer_connects<'a>(model: &'a Xml, part: &'a Xml) -> impl Iterator<Item = (&'a Xml, bool)> {
    model
        .children_named("connect")
        .map(|c| (c, true))
        .chain(part.children_named("connect").map(|c| (c, false)))
}

fn export_thread(
    model: &Xml,
    part: &Xml,
    thread: &Xml,
    catalogue: &Catalogue,
    first: bool,
) -> Result<Exported, String> {
    let mut notes = Vec::new();
    // The file facts `import finroc` kept: `version` and the root tag hold for every
    // file written; `defaultname` and `dependencies` are the first file's.
    let doc = model.value("doc").unwrap_or_default();
    let facts: Vec<(&str, &str)> = doc.split("; ").filter_map(|f| f.split_once(": ")).collect();
    let fact = |k: &str| facts.iter().find(|(key, _)| *key == k).map(|(_, v)| *v);
    let container = thread.value("name").unwrap_or_default().to_string();
    let span = model.name_span;
    let version = fact("version").and_then(|v| v.parse().ok());
    let tops = top_elements(thread, catalogue, &mut notes);
    let mut dependencies: Vec<String> = Vec::new();
    match fact("dependencies").filter(|_| first) {
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
    let edges = thread_edges(model, part, thread, &tops, &mut notes);
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
    let defaultname = match fact("defaultname").filter(|_| first) {
        Some(d) => Some(named(d, span)),
        None if !first => Some(named(&container, span)),
        None => None,
    };
    Ok(Exported {
        container,
        doc: Finstructable {
            file: span.file,
            root_tag: fact("root").unwrap_or("Finstructable").to_string(),
            root_span: span,
            version,
            defaultname,
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

/// The modules and groups of `thread` whose types are FINROC catalogue types (a note
/// for each of the others).
fn top_elements<'a, 'c>(
    thread: &'a Xml,
    catalogue: &'c Catalogue,
    notes: &mut Vec<String>,
) -> Vec<Top<'a, 'c>> {
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
    tops
}

/// The edges between the exported elements of `thread`: its own `<connect>`s and
/// those of the application and `part` that lead into it (a note for each whose end
/// is not a port of an exported element).
fn thread_edges(
    model: &Xml,
    part: &Xml,
    thread: &Xml,
    tops: &[Top<'_, '_>],
    notes: &mut Vec<String>,
) -> Vec<Edge> {
    let mut edges = Vec::new();
    let outer = outer_connects(model, part).filter_map(|(c, at_model)| {
        let from = thread_local(c.value("from")?, at_model, part, thread)?;
        let to = thread_local(c.value("to")?, at_model, part, thread)?;
        Some((c, from, to))
    });
    let own = thread
        .children_named("connect")
        .filter_map(|c| Some((c, c.value("from")?, c.value("to")?)));
    for (c, from, to) in own.chain(outer) {
        match (end(from, tops, c.span), end(to, tops, c.span)) {
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
    edges
}

/// `simulation/pose` → `Simulation/Sensor Output/Pose`.
fn end(path: &str, tops: &[Top<'_, '_>], span: Span) -> Option<EdgeEnd> {
    let (first, port) = path.split_once('/')?;
    let t = tops.iter().find(|t| t.xml.value("name") == Some(first))?;
    let p = t.component.ports.iter().find(|p| p.member == port)?;
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
