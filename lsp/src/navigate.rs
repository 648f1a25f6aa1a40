//! Go to definition: from a connection end to the module instance and to the port's
//! declaration in its manifest; from a module's `type=` to the module type; from a
//! group's `type=` to the group type.

use crate::convert::Spans;
use crate::request::{self, Reply};
use crate::server::Server;
use ferroc_compiler::ir::{Application, ParamSource};
use ferroc_compiler::library::LibrarySet;
use ferroc_compiler::source::{SourceMap, Span};
use ferroc_compiler::syntax::xml::{self, Element};
use ferroc_compiler::CheckResult;
use lsp_server::Request;
use lsp_types::{GotoDefinitionParams, Location};

pub fn definition(server: &Server, req: &Request) -> Reply {
    let p: GotoDefinitionParams = request::params(req)?;
    let (result, here) = match request::checked_at(server, &p.text_document_position_params) {
        Ok(found) => found,
        Err(reply) => return reply,
    };
    let targets = targets(&result, here);
    let mut spans = Spans::new(&result.sources, server.enc);
    let mut locations: Vec<Location> = Vec::new();
    for span in targets {
        if let Some(l) = spans.location(span) {
            if !locations.contains(&l) {
                locations.push(l);
            }
        }
    }
    Ok(Some(serde_json::to_value(locations).unwrap_or_default()))
}

/// Whether the cursor (an empty span) is inside `span`, its end included (the cursor
/// right after a word still names it).
pub fn covers(span: Span, here: Span) -> bool {
    span.file == here.file && span.start <= here.start && here.start <= span.end
}

/// The places the text at `here` refers to.
pub fn targets(result: &CheckResult, here: Span) -> Vec<Span> {
    let mut out = Vec::new();
    if let Some(app) = &result.app {
        connection_ends(app, &result.libraries, here, &mut out);
        module_types(app, &result.libraries, here, &mut out);
        config_entries(app, here, &mut out);
    }
    if out.is_empty() {
        group_types(&result.sources, &result.libraries, here, &mut out);
    }
    out
}

fn connection_ends(app: &Application, libs: &LibrarySet, here: Span, out: &mut Vec<Span>) {
    for c in &app.connections {
        for (span, end) in [(c.from_span, c.from), (c.to_span, c.to)] {
            if covers(span, here) {
                out.push(app.element(end.element()).name_span);
                if let Some(view) = app.view(libs, end) {
                    out.push(view.span);
                }
            }
        }
    }
}

fn module_types(app: &Application, libs: &LibrarySet, here: Span, out: &mut Vec<Span>) {
    for (_, m) in app.modules() {
        if covers(m.type_span, here) {
            out.push(libs.get(m.library).module_types[m.type_index].span);
            return;
        }
    }
}

/// `config="file#/entry"` → the entry's `<value>` in the config file.
fn config_entries(app: &Application, here: Span, out: &mut Vec<Span>) {
    for (_, m) in app.modules() {
        for value in &m.params {
            if let ParamSource::Config(Ok((_, entry))) = &value.source {
                if covers(value.source_span, here) {
                    out.push(*entry);
                    return;
                }
            }
        }
    }
}

/// `<group type="T">` → the `<group-type name="T">` of the model's files or of a library.
fn group_types(sources: &SourceMap, libs: &LibrarySet, here: Span, out: &mut Vec<Span>) {
    let text = &sources.get(here.file).text;
    let Ok(root) = xml::parse(here.file, text, 256) else {
        return;
    };
    let Some(group) = find_element(&root, here, &|e| e.name.as_str() == "group") else {
        return;
    };
    let Some(ty) = group.attr("type").filter(|a| covers(a.value_span, here)) else {
        return;
    };
    let wanted = ty.value;
    for (id, _) in sources.files() {
        let Ok(tree) = xml::parse(id, &sources.get(id).text, 256) else {
            continue;
        };
        walk(&tree, &mut |e| {
            if e.name.as_str() == "group-type" && e.value("name") == Some(wanted) {
                out.push(e.name_span);
            }
        });
    }
    for lib in &libs.libraries {
        for gt in &lib.group_types {
            let qualified = format!("{}.{}", lib.name, gt.name);
            if gt.name == wanted || qualified == wanted {
                out.push(gt.element.name_span);
            }
        }
    }
}

/// The innermost element containing `here` that `pick` accepts.
pub fn find_element<'e>(
    root: &'e Element,
    here: Span,
    pick: &dyn Fn(&Element) -> bool,
) -> Option<&'e Element> {
    if !covers(root.span, here) {
        return None;
    }
    for child in root.children.iter() {
        if let Some(found) = find_element(child, here, pick) {
            return Some(found);
        }
    }
    pick(root).then_some(root)
}

pub fn walk(e: &Element, f: &mut dyn FnMut(&Element)) {
    f(e);
    for c in e.children.iter() {
        walk(c, f);
    }
}

/// Find references: every connection end and module `type=` that names the same
/// thing as the text at the cursor — a connection end (that port of that instance), a
/// port or module type declaration (every use of it), a module instance's name.
pub fn references(server: &Server, req: &Request) -> Reply {
    let p: lsp_types::ReferenceParams = request::params(req)?;
    let (result, here) = match request::checked_at(server, &p.text_document_position) {
        Ok(found) => found,
        Err(reply) => return reply,
    };
    if let Some(found) = group_type_uses(&result.sources, here, p.context.include_declaration) {
        let mut spans = Spans::new(&result.sources, server.enc);
        let locations: Vec<Location> = found
            .into_iter()
            .filter_map(|s| spans.location(s))
            .collect();
        return Ok(Some(serde_json::to_value(locations).unwrap_or_default()));
    }
    let Some(app) = &result.app else {
        return Ok(Some(serde_json::json!([])));
    };
    let uses = uses(app, &result.libraries);
    let same: Box<dyn Fn(&Use) -> bool> = if let Some(u) = uses.iter().find(|u| covers(u.at, here))
    {
        let key = (u.instance, u.decl);
        Box::new(move |v: &Use| (v.instance, v.decl) == key)
    } else if let Some(u) = uses.iter().find(|u| covers(u.decl, here)) {
        let decl = u.decl;
        Box::new(move |v: &Use| v.decl == decl)
    } else if let Some(u) = uses
        .iter()
        .find(|u| u.instance.is_some_and(|i| covers(i, here)))
    {
        let instance = u.instance;
        Box::new(move |v: &Use| v.instance == instance)
    } else {
        return Ok(Some(serde_json::json!([])));
    };
    let mut spans = Spans::new(&result.sources, server.enc);
    let mut locations: Vec<Location> = Vec::new();
    for u in uses.iter().filter(|u| same(u)) {
        let mut found = vec![u.at];
        if p.context.include_declaration {
            found.push(u.decl);
        }
        for span in found {
            if let Some(l) = spans.location(span) {
                if !locations.contains(&l) {
                    locations.push(l);
                }
            }
        }
    }
    Ok(Some(serde_json::to_value(locations).unwrap_or_default()))
}

/// References of a group type, from its `<group-type name>` or from an instance's
/// `<group type>`: the `type=` of every `<group>` of the model's files that names it
/// (and the declaration's name when asked). `None`: the cursor is on neither.
fn group_type_uses(sources: &SourceMap, here: Span, declaration: bool) -> Option<Vec<Span>> {
    let text = &sources.get(here.file).text;
    let root = xml::parse(here.file, text, 256).ok()?;
    let at = find_element(&root, here, &|e| {
        matches!(e.name.as_str(), "group" | "group-type")
    })?;
    let attr = if at.name.as_str() == "group" {
        "type"
    } else {
        "name"
    };
    let named = at.attr(attr).filter(|a| covers(a.value_span, here))?;
    let wanted = named.value.rsplit('.').next().unwrap_or(named.value);
    let mut out = Vec::new();
    for (id, _) in sources.files() {
        let Ok(tree) = xml::parse(id, &sources.get(id).text, 256) else {
            continue;
        };
        walk(&tree, &mut |e| {
            let short = |v: &str| v.rsplit('.').next() == Some(wanted);
            if e.name.as_str() == "group" && e.value("type").is_some_and(short) {
                out.push(e.value_span("type"));
            }
            if declaration && e.name.as_str() == "group-type" && e.value("name") == Some(wanted) {
                out.push(e.value_span("name"));
            }
        });
    }
    Some(out)
}

/// A use in the model: a connection end (the instance and the port declaration it
/// names) or a module's `type=` (the module type).
struct Use {
    at: Span,
    instance: Option<Span>,
    decl: Span,
}

fn uses(app: &Application, libs: &LibrarySet) -> Vec<Use> {
    let mut out = Vec::new();
    for c in &app.connections {
        for (at, end) in [(c.from_span, c.from), (c.to_span, c.to)] {
            let instance = app.element(end.element()).name_span;
            let decl = app.view(libs, end).map_or(instance, |v| v.span);
            out.push(Use {
                at,
                instance: Some(instance),
                decl,
            });
        }
    }
    for (_, m) in app.modules() {
        let ty = &libs.get(m.library).module_types[m.type_index];
        out.push(Use {
            at: m.type_span,
            instance: None,
            decl: ty.span,
        });
    }
    out
}
