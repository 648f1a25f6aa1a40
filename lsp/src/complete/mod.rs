//! Completion from the text before the cursor: element names a parent may hold and
//! attribute names an element takes (the vocabulary table the validator and the XSDs
//! use), enumerated attribute values, units in `unit=` (ferroc-values' table) and
//! after the number of a `<param>` value (those of the parameter's dimension), module types of the libraries in scope in
//! `type=`, and port paths in `from=`/`to=` (outputs first in `from=`, inputs first in
//! `to=`, ports of the other end's type and unit before the rest).

use crate::request::{self, Reply};
use crate::server::Server;
use ferroc_compiler::ir::{Application, ElementId, ElementKind, Endpoint};
use ferroc_compiler::library::{LibrarySet, ParamDecl, PortDir};
use ferroc_compiler::syntax::vocabulary::{self, AttrKind, ElementSpec};
use ferroc_compiler::types::Type;
use ferroc_compiler::CheckResult;
use lsp_server::Request;
use lsp_types::{
    CompletionItem, CompletionItemKind, CompletionList, CompletionParams, CompletionTextEdit,
    TextEdit,
};
use place::{context, Place};

mod place;

/// At most this many items are sent (a 10,000-module model has ~50,000 ports); the
/// list says it is incomplete, so the client asks again as the user types.
const MAX_ITEMS: usize = 1000;

pub fn completion(server: &Server, req: &Request) -> Reply {
    let p: CompletionParams = request::params(req)?;
    let Some(at) = request::at(server, &p.text_document_position) else {
        return Ok(Some(serde_json::Value::Null));
    };
    let Some(doc) = server.docs.get(&at.path) else {
        return Ok(Some(serde_json::Value::Null));
    };
    let before = &doc.text[..at.offset];
    let latest = server.latest(&at.path);
    let items = match context(before) {
        Some(Place::Tag { parents, partial }) => tags(&parents, &partial),
        Some(Place::Attr { parents, tag, .. }) => attrs(&parents, &tag),
        Some(Place::Value {
            parents,
            tag,
            attr,
            typed,
            other,
        }) => values(
            &parents,
            &tag,
            &attr,
            &typed,
            other.as_deref(),
            latest.as_deref(),
        ),
        Some(Place::ParamValue {
            parents,
            param,
            typed,
        }) => {
            let decl = latest
                .as_deref()
                .and_then(|r| param_decl(r, &parents, &param));
            let (_, partial) = value_unit(&typed).unwrap_or_default();
            let range =
                doc.lines
                    .range(&doc.text, at.offset - partial.len(), at.offset, server.enc);
            let mut items = value_units(&typed, decl);
            for it in &mut items {
                it.text_edit = Some(CompletionTextEdit::Edit(TextEdit::new(
                    range,
                    it.label.clone(),
                )));
            }
            items
        }
        None => Vec::new(),
    };
    let incomplete = items.len() > MAX_ITEMS;
    let list = CompletionList {
        is_incomplete: incomplete,
        items: items.into_iter().take(MAX_ITEMS).collect(),
    };
    Ok(Some(serde_json::to_value(list).unwrap_or_default()))
}

/// The vocabulary entry of the innermost open element, found from the root down.
fn spec_of(parents: &[(String, Option<String>)]) -> Option<&'static ElementSpec> {
    let (root, rest) = parents.split_first()?;
    let mut spec = vocabulary::ELEMENTS
        .iter()
        .find(|e| e.tag == root.0 && ["application", "fragment", "library"].contains(&e.key))?;
    for (tag, _) in rest {
        spec = vocabulary::spec(vocabulary::child_key(spec, tag)?);
    }
    Some(spec)
}

fn child_spec(parents: &[(String, Option<String>)], tag: &str) -> Option<&'static ElementSpec> {
    if parents.is_empty() {
        return vocabulary::ELEMENTS.iter().find(|e| e.tag == tag);
    }
    let parent = spec_of(parents)?;
    Some(vocabulary::spec(vocabulary::child_key(parent, tag)?))
}

fn item(label: &str, kind: CompletionItemKind, detail: Option<String>) -> CompletionItem {
    CompletionItem {
        label: label.to_string(),
        kind: Some(kind),
        detail,
        ..CompletionItem::default()
    }
}

fn tags(parents: &[(String, Option<String>)], partial: &str) -> Vec<CompletionItem> {
    let names: Vec<&str> = match spec_of(parents) {
        Some(parent) => parent
            .children
            .iter()
            .map(|k| vocabulary::spec(k).tag)
            .collect(),
        None if parents.is_empty() => vec!["application", "fragment", "library"],
        None => Vec::new(),
    };
    let mut out: Vec<CompletionItem> = Vec::new();
    for name in names {
        if name.starts_with(partial) && !out.iter().any(|i| i.label == name) {
            out.push(item(name, CompletionItemKind::CLASS, None));
        }
    }
    out
}

fn attrs(parents: &[(String, Option<String>)], tag: &str) -> Vec<CompletionItem> {
    let Some(spec) = child_spec(parents, tag) else {
        return Vec::new();
    };
    let mut out: Vec<CompletionItem> = spec
        .attrs
        .iter()
        .map(|a| {
            let detail = a.required.then(|| "required".to_string());
            let mut it = item(a.name, CompletionItemKind::PROPERTY, detail);
            it.insert_text = Some(format!("{}=\"", a.name));
            it
        })
        .collect();
    for common in vocabulary::COMMON_ATTRS {
        out.push(item(common, CompletionItemKind::PROPERTY, None));
    }
    out
}

fn values(
    parents: &[(String, Option<String>)],
    tag: &str,
    attr: &str,
    typed: &str,
    other: Option<&str>,
    result: Option<&CheckResult>,
) -> Vec<CompletionItem> {
    let spec = child_spec(parents, tag);
    let kind = spec
        .and_then(|s| s.attrs.iter().find(|a| a.name == attr))
        .map(|a| a.kind);
    if let Some(AttrKind::Choice(choices)) = kind {
        return choices
            .iter()
            .map(|c| item(c, CompletionItemKind::ENUM_MEMBER, None))
            .collect();
    }
    if attr == "unit" {
        return units(typed);
    }
    if let Some(AttrKind::Bool) = kind {
        return ["true", "false"]
            .iter()
            .map(|c| item(c, CompletionItemKind::ENUM_MEMBER, None))
            .collect();
    }
    let Some(result) = result else {
        return Vec::new();
    };
    match (tag, attr) {
        ("module", "type") => module_types(result),
        ("connect", "from" | "to") => match &result.app {
            Some(app) => ports(
                app,
                &result.libraries,
                parents,
                attr == "from",
                typed,
                other,
            ),
            None => Vec::new(),
        },
        _ => Vec::new(),
    }
}

/// The units of ferroc-values' table that start with what is typed.
fn units(typed: &str) -> Vec<CompletionItem> {
    (ferroc_compiler::units::SUGGESTED.iter())
        .filter(|u| u.starts_with(typed))
        .map(|u| {
            let detail = ferroc_compiler::units::parse_unit(u)
                .ok()
                .map(|p| ferroc_compiler::units::describe_dimension(&p.dimension));
            item(u, CompletionItemKind::UNIT, detail)
        })
        .collect()
}

/// A parameter value being typed as a number and then a unit: the unit typed so far
/// (`1.5 km` → `("1.5", "km")`); `None` before a number is complete.
fn value_unit(typed: &str) -> Option<(&str, &str)> {
    let (number, _) = ferroc_compiler::values::split_number(typed);
    if number.is_empty() || number.parse::<f64>().is_err() {
        return None;
    }
    let rest = typed.trim_start()[number.len()..].trim_start();
    (!rest.contains(char::is_whitespace)).then_some((number, rest))
}

/// Units after the number of a parameter value: those of the parameter's dimension
/// (seconds and the like for a duration); none for a parameter without a unit; every
/// unit when the parameter is not known (no check yet).
fn value_units(typed: &str, decl: Option<&ParamDecl>) -> Vec<CompletionItem> {
    let Some((_, partial)) = value_unit(typed) else {
        return Vec::new();
    };
    let dimension = match decl {
        None => None,
        Some(d) => match (&d.unit, &d.ty) {
            (Some(u), _) => Some(u.dimension),
            (None, Type::Duration) => ferroc_compiler::units::parse_unit("s")
                .ok()
                .map(|u| u.dimension),
            (None, _) => return Vec::new(),
        },
    };
    let mut items = units(partial);
    items.retain(|it| {
        let unit = ferroc_compiler::units::parse_unit(&it.label);
        dimension.is_none_or(|want| unit.is_ok_and(|u| u.dimension == want))
    });
    items
}

/// The declaration of parameter `param` of the module the open elements `parents`
/// end in, as the last check resolved it.
fn param_decl<'r>(
    result: &'r CheckResult,
    parents: &[(String, Option<String>)],
    param: &str,
) -> Option<&'r ParamDecl> {
    let app = result.app.as_ref()?;
    let (last, _) = parents.last()?;
    if last != "module" {
        return None;
    }
    // Element 0 is the application; parts are its children.
    let mut here = ElementId(0);
    for (tag, name) in parents.iter().skip(1) {
        if matches!(tag.as_str(), "part" | "thread" | "group" | "module") {
            here = app.child(here, name.as_deref()?)?;
        }
    }
    app.module_type(&result.libraries, here)?.param(param)
}

fn module_types(result: &CheckResult) -> Vec<CompletionItem> {
    let mut out = Vec::new();
    for lib in &result.libraries.libraries {
        for ty in &lib.module_types {
            out.push(item(
                &ty.qualified,
                CompletionItemKind::CLASS,
                Some(format!("{:?}", ty.kind).to_lowercase()),
            ));
        }
    }
    out
}

/// Port paths relative to the connection's scope (the names of the enclosing parts,
/// thread containers and groups).
fn ports(
    app: &Application,
    libs: &LibrarySet,
    parents: &[(String, Option<String>)],
    from: bool,
    typed: &str,
    other: Option<&str>,
) -> Vec<CompletionItem> {
    let scope: Vec<&str> = parents
        .iter()
        .filter(|(t, _)| matches!(t.as_str(), "part" | "thread" | "group"))
        .filter_map(|(_, n)| n.as_deref())
        .collect();
    let scope = scope.join("/");
    let prefix = if scope.is_empty() {
        String::new()
    } else {
        format!("{scope}/")
    };
    let mut found: Vec<(String, Endpoint, PortDir)> = Vec::new();
    for (i, e) in app.elements.iter().enumerate() {
        let id = ferroc_compiler::ir::ElementId(i as u32);
        let Some(rel) = app.path(id).strip_prefix(&prefix).map(str::to_string) else {
            continue;
        };
        if rel.is_empty() {
            continue;
        }
        match &e.kind {
            ElementKind::Module(_) => {
                for (port, decl) in app.module_ports(libs, id) {
                    found.push((
                        format!("{rel}/{}", decl.name),
                        Endpoint::Port { element: id, port },
                        decl.dir,
                    ));
                }
            }
            ElementKind::Group => {
                for (port, gp) in e.group_ports.iter().enumerate() {
                    found.push((
                        format!("{rel}/{}", gp.name),
                        Endpoint::GroupPort {
                            element: id,
                            port: port as u32,
                        },
                        gp.dir,
                    ));
                }
            }
            _ => {}
        }
        if found.len() > 200_000 {
            break;
        }
    }
    let other_view = other
        .and_then(|o| found.iter().find(|(p, _, _)| p == o))
        .and_then(|(_, ep, _)| app.view(libs, *ep));
    let want = if from { PortDir::Out } else { PortDir::In };
    let mut items: Vec<CompletionItem> = found
        .iter()
        .filter(|(p, _, _)| p.starts_with(typed) || typed.is_empty())
        .map(|(path, ep, dir)| {
            let view = app.view(libs, *ep);
            let fits = match (&view, &other_view) {
                (Some(v), Some(o)) => {
                    v.ty.to_string() == o.ty.to_string()
                        && v.unit.map(|u| u.to_string()) == o.unit.map(|u| u.to_string())
                }
                _ => false,
            };
            let rank = match (*dir == want, fits) {
                (true, true) => 0,
                (true, false) => 1,
                _ => 2,
            };
            let detail = view.map(|v| {
                let unit = v.unit.map(|u| format!(" [{u}]")).unwrap_or_default();
                format!(
                    "{} {}{unit}",
                    if v.dir == PortDir::In { "in" } else { "out" },
                    v.ty
                )
            });
            let mut it = item(path, CompletionItemKind::FIELD, detail);
            it.sort_text = Some(format!("{rank}{path}"));
            it
        })
        .collect();
    items.sort_by(|a, b| a.sort_text.cmp(&b.sort_text));
    items
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offers_values_units_and_tags() {
        let units: Vec<String> = values(&[], "port", "unit", "m/", None, None)
            .into_iter()
            .map(|i| i.label)
            .collect();
        assert!(units.contains(&"m/s".to_string()), "{units:?}");
        assert!(units.iter().all(|u| u.starts_with("m/")), "{units:?}");
        let kinds: Vec<String> = values(
            &[
                ("application".into(), None),
                ("part".into(), Some("p".into())),
                ("thread".into(), Some("t".into())),
            ],
            "connect",
            "on-full",
            "",
            None,
            None,
        )
        .into_iter()
        .map(|i| i.label)
        .collect();
        assert!(kinds.contains(&"drop-oldest".to_string()), "{kinds:?}");
        assert_eq!(value_unit("1.5 km"), Some(("1.5", "km")));
        assert_eq!(value_unit("-2e3"), Some(("-2e3", "")));
        assert_eq!(value_unit("fast"), None, "no number");
        assert_eq!(value_unit("1 2"), Some(("1", "2")), "a unit is one word");
        assert_eq!(value_unit("1 m s"), None);
        assert!(value_units("1 ", None).iter().any(|i| i.label == "km/h"));
        let names: Vec<String> = tags(&[("application".into(), None)], "pa")
            .into_iter()
            .map(|i| i.label)
            .collect();
        assert_eq!(names, ["part"]);
    }
}
