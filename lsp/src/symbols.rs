//! Document symbols (the element tree, named by `name=`) and workspace symbols (the
//! named elements of every model checked, and the module types of their libraries).

use crate::convert::Spans;
use crate::position::LineIndex;
use crate::request::{self, Reply};
use crate::server::Server;
use ferroc_compiler::source::FileId;
use ferroc_compiler::syntax::xml::{self, Element};
use lsp_server::Request;
use lsp_types::{
    DocumentSymbol, DocumentSymbolParams, Location, SymbolInformation, SymbolKind,
    WorkspaceSymbolParams,
};

/// Deeper elements are left out of the outline (the parser's own limit is 256).
const MAX_DEPTH: usize = 64;
/// At most this many workspace symbols are sent.
const MAX_WORKSPACE: usize = 2000;

pub fn document_symbols(server: &Server, req: &Request) -> Reply {
    let p: DocumentSymbolParams = request::params(req)?;
    let doc =
        crate::documents::path_of(&p.text_document.uri).and_then(|path| server.docs.get(&path));
    let Some(doc) = doc else {
        return Ok(Some(serde_json::Value::Null));
    };
    // A half-typed file has no tree: no outline until it parses again.
    let Ok(root) = xml::parse(FileId(0), &doc.text, 256) else {
        return Ok(Some(serde_json::json!([])));
    };
    let symbols = vec![symbol(&root, &doc.text, &doc.lines, server, 0)];
    Ok(Some(serde_json::to_value(symbols).unwrap_or_default()))
}

#[allow(deprecated)] // `deprecated` is a field the type still requires
fn symbol(
    e: &Element,
    text: &str,
    lines: &LineIndex,
    server: &Server,
    depth: usize,
) -> DocumentSymbol {
    let name = e
        .value("name")
        .map_or_else(|| e.name.to_string(), str::to_string);
    let detail = e
        .value("type")
        .map(str::to_string)
        .or_else(|| e.name.as_str().ne(&name).then(|| e.name.to_string()));
    let children: Vec<DocumentSymbol> = if depth < MAX_DEPTH {
        e.children
            .iter()
            .map(|c| symbol(c, text, lines, server, depth + 1))
            .collect()
    } else {
        Vec::new()
    };
    let range = lines.range(text, e.span.start as usize, e.span.end as usize, server.enc);
    let selection = lines.range(
        text,
        e.name_span.start as usize,
        e.name_span.end as usize,
        server.enc,
    );
    DocumentSymbol {
        name,
        detail,
        kind: kind(e.name.as_str()),
        tags: None,
        deprecated: None,
        range,
        selection_range: selection,
        children: (!children.is_empty()).then_some(children),
    }
}

fn kind(tag: &str) -> SymbolKind {
    match tag {
        "application" | "library" | "fragment" => SymbolKind::FILE,
        "part" => SymbolKind::PACKAGE,
        "thread" => SymbolKind::EVENT,
        "group" | "group-type" => SymbolKind::NAMESPACE,
        "module" => SymbolKind::OBJECT,
        "module-type" | "type" => SymbolKind::CLASS,
        "connect" => SymbolKind::OPERATOR,
        "param" => SymbolKind::PROPERTY,
        "in" | "out" | "sensor-in" | "sensor-out" | "controller-in" | "controller-out"
        | "group-port" | "port" => SymbolKind::FIELD,
        _ => SymbolKind::KEY,
    }
}

#[allow(deprecated)]
pub fn workspace_symbols(server: &Server, req: &Request) -> Reply {
    let p: WorkspaceSymbolParams = request::params(req)?;
    let query = p.query.to_lowercase();
    let mut out: Vec<SymbolInformation> = Vec::new();
    for result in server.results.values() {
        let mut spans = Spans::new(&result.sources, server.enc);
        if let Some(app) = &result.app {
            for (i, e) in app.elements.iter().enumerate().skip(1) {
                if out.len() >= MAX_WORKSPACE {
                    break;
                }
                let path = app.path(ferroc_compiler::ir::ElementId(i as u32));
                if !path.to_lowercase().contains(&query) {
                    continue;
                }
                let Some(location) = spans.location(e.name_span) else {
                    continue;
                };
                push(&mut out, path, SymbolKind::OBJECT, location);
            }
        }
        for lib in &result.libraries.libraries {
            for ty in &lib.module_types {
                if out.len() >= MAX_WORKSPACE || !ty.qualified.to_lowercase().contains(&query) {
                    continue;
                }
                if let Some(location) = spans.location(ty.span) {
                    push(&mut out, ty.qualified.clone(), SymbolKind::CLASS, location);
                }
            }
        }
    }
    Ok(Some(serde_json::to_value(out).unwrap_or_default()))
}

#[allow(deprecated)]
fn push(out: &mut Vec<SymbolInformation>, name: String, kind: SymbolKind, location: Location) {
    if out.iter().any(|s| s.name == name && s.location == location) {
        return;
    }
    out.push(SymbolInformation {
        name,
        kind,
        tags: None,
        deprecated: None,
        location,
        container_name: None,
    });
}
