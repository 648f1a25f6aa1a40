//! Reads a FINROC application or group file into a [`Finstructable`], as FINROC's
//! `tFinstructable::LoadXml` does: the root's name is not checked, unknown tags are
//! skipped with a finding (FINROC logs `Unknown XML tag`), a broken part is reported at
//! its place and left out; nothing here panics or stops the rest of the file.

use super::finstructable::*;
use super::text::{comma_items, percent_decode, ValueSpan};
use crate::checks::f101_finroc_structure::CHECK;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics, Severity};
use ferroc_diagnostics::source::{FileId, Span};
use ferroc_syntax::Element as Xml;

/// Reads a parsed application or group file.
pub fn read(file: FileId, root: &Xml, out: &mut Diagnostics) -> Finstructable {
    let version = root.attr("version").and_then(|a| match a.value.trim().parse::<u32>() {
        Ok(v) => Some(v),
        Err(_) => {
            out.push(
                Diagnostic::new(&CHECK, a.value_span, format!("`version=\"{}\"` is not a number", a.value))
                    .label("FINROC reads this as version 0 (legacy paths)")
                    .help("FINROC writes `version=\"1703\"`; remove the attribute for the legacy format"),
            );
            None
        }
    });
    let mut doc = Finstructable {
        file,
        root_tag: root.name.to_string(),
        root_span: root.name_span,
        version,
        defaultname: named_attr(root, "defaultname"),
        dependencies: Vec::new(),
        has_dependencies: root.attr("dependencies").is_some(),
        interfaces: Vec::new(),
        elements: Vec::new(),
        edges: Vec::new(),
        links: Vec::new(),
    };
    if let Some(a) = root.attr("dependencies") {
        let spans = ValueSpan::new(a.value_span, a.value);
        doc.dependencies = comma_items(a.value)
            .map(|d| Named {
                text: d.to_string(),
                span: spans.of(a.value, d),
            })
            .collect();
    }
    for child in &root.children {
        match child.name.as_str() {
            "interface" => {
                if let Some(i) = interface(child, out) {
                    doc.interfaces.push(i)
                }
            }
            "element" => {
                if let Some(e) = element(child, out) {
                    doc.elements.push(e)
                }
            }
            "edge" => {
                if let Some(e) = edge(child, version.is_some(), out) {
                    doc.edges.push(e)
                }
            }
            "parameter" => {
                if let Some(l) = legacy_link(child, out) {
                    doc.links.push(l)
                }
            }
            "parameter_links" => link_tree(child, &mut Vec::new(), &mut doc.links, out),
            _ => unknown_tag(child, "a FINROC application or group file", out),
        }
    }
    doc
}

fn named_attr(e: &Xml, name: &str) -> Option<Named> {
    e.attr(name).map(|a| Named {
        text: a.value.to_string(),
        span: a.value_span,
    })
}

fn unknown_tag(e: &Xml, place: &str, out: &mut Diagnostics) {
    out.push(
        Diagnostic::new(
            &CHECK,
            e.name_span,
            format!("<{}> is not part of {place}", e.name),
        )
        .label("FINROC logs `Unknown XML tag` and ignores it")
        .help("remove it, or check the spelling against FINROC's format")
        .severity(Severity::Warning),
    );
}

/// A required attribute; reports its absence at the tag with what FINROC does instead.
fn required(e: &Xml, name: &str, consequence: &str, out: &mut Diagnostics) -> Option<Named> {
    let found = named_attr(e, name);
    if found.is_none() {
        out.push(
            Diagnostic::new(&CHECK, e.name_span, format!("<{}> has no `{name}`", e.name))
                .label(consequence.to_string())
                .help(format!("add `{name}=\"…\"`")),
        );
    }
    found
}

fn interface(e: &Xml, out: &mut Diagnostics) -> Option<Interface> {
    let name = required(
        e,
        "name",
        "FINROC cannot tell which interface these ports belong to",
        out,
    )?;
    let mut ports = Vec::new();
    for p in &e.children {
        if p.name != "port" {
            unknown_tag(p, "an <interface>", out);
            continue;
        }
        let Some(pname) = required(p, "name", "FINROC creates no port from it", out) else {
            continue;
        };
        let flag = |a| p.value(a).is_some_and(|v| v.trim() == "true");
        ports.push(InterfacePort {
            name: pname,
            ty: named_attr(p, "type"),
            output: flag("output"),
            shared: flag("shared"),
            span: p.span,
        });
    }
    Some(Interface {
        name,
        span: e.span,
        ports,
    })
}

fn element(e: &Xml, out: &mut Diagnostics) -> Option<Element> {
    let skipped = "FINROC cannot create it and skips it with everything inside";
    let name = required(e, "name", skipped, out)?;
    let group = required(e, "group", skipped, out);
    let ty = required(e, "type", skipped, out);
    let mut element = Element {
        name,
        group,
        ty,
        span: e.span,
        constructor: Vec::new(),
        parameters: None,
        children: Vec::new(),
    };
    for (i, c) in e.children.iter().enumerate() {
        match c.name.as_str() {
            "constructor" if i == 0 => element.constructor = static_params(c, out),
            "constructor" => out.push(
                Diagnostic::new(
                    &CHECK,
                    c.name_span,
                    "<constructor> is not the first child of its <element>",
                )
                .label("FINROC reads constructor parameters only from the first child")
                .help("move <constructor> before <parameters>")
                .severity(Severity::Warning),
            ),
            "parameters" => element.parameters = Some(static_params(c, out)),
            "element" => element.children.extend(self::element(c, out)),
            _ => unknown_tag(c, "an <element>", out),
        }
    }
    Some(element)
}

fn static_params(e: &Xml, out: &mut Diagnostics) -> Vec<StaticParam> {
    let mut list = Vec::new();
    for p in &e.children {
        if p.name != "parameter" {
            unknown_tag(p, "a parameter list", out);
            continue;
        }
        let Some(name) = required(p, "name", "FINROC cannot match it to a parameter", out) else {
            continue;
        };
        let value_span = if p.text().is_empty() {
            p.span
        } else {
            p.text_span()
        };
        list.push(StaticParam {
            name,
            value: Named {
                text: p.text().to_string(),
                span: value_span,
            },
            attrs: p
                .attrs()
                .filter(|a| a.name != "name")
                .map(|a| {
                    (
                        a.name.to_string(),
                        Named {
                            text: a.value.to_string(),
                            span: a.value_span,
                        },
                    )
                })
                .collect(),
            span: p.span,
        });
    }
    list
}

fn edge(e: &Xml, encoded: bool, out: &mut Diagnostics) -> Option<Edge> {
    let dropped = "FINROC creates no connection from it";
    let src = required(e, "src", dropped, out);
    let dest = required(e, "dest", dropped, out);
    let (src, dest) = (end(src?, encoded, out)?, end(dest?, encoded, out)?);
    if src.scheme.is_some() && dest.scheme.is_some() {
        out.push(
            Diagnostic::new(
                &CHECK,
                e.name_span,
                "both ends of this edge have a URI scheme",
            )
            .label("FINROC throws `Only one port may have an address with an URI scheme`")
            .help("one end must be a port of this application"),
        );
        return None;
    }
    let mut edge = Edge {
        src,
        dest,
        flags: Vec::new(),
        conversion: None,
        params: Vec::new(),
        span: e.span,
    };
    if let Some(a) = e.attr("flags") {
        edge.flags = flags(a.value, ValueSpan::new(a.value_span, a.value), out);
    }
    for c in &e.children {
        match c.name.as_str() {
            "conversion" if encoded => {
                edge.conversion = Some(Conversion {
                    attrs: c
                        .attrs()
                        .map(|a| {
                            (
                                a.name.to_string(),
                                Named {
                                    text: a.value.to_string(),
                                    span: a.value_span,
                                },
                            )
                        })
                        .collect(),
                    span: c.span,
                })
            }
            "conversion" => out.push(
                Diagnostic::new(
                    &CHECK,
                    c.name_span,
                    "<conversion> in a file without `version`",
                )
                .label("FINROC reads conversions only from version-1703 files")
                .help("add `version=\"1703\"` to the root (and percent-encode the edge paths)")
                .severity(Severity::Warning),
            ),
            "parameter" => {
                if let (Some(n), v) = (named_attr(c, "name"), c.text().to_string()) {
                    let span = c.text_span();
                    edge.params.push((n, Named { text: v, span }));
                }
            }
            _ => unknown_tag(c, "an <edge>", out),
        }
    }
    Some(edge)
}

/// Splits an edge end into scheme and path segments (percent-decoded in 1703 files).
fn end(raw: Named, encoded: bool, out: &mut Diagnostics) -> Option<EdgeEnd> {
    let text = raw.text.as_str();
    let scheme_len = text
        .find(':')
        .filter(|&i| {
            i > 0
                && text[..i].starts_with(|c: char| c.is_ascii_alphabetic())
                && text[..i]
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || "+.-".contains(c))
                && !text[..i].contains('/')
        })
        .filter(|_| encoded);
    let (scheme, path) = match scheme_len {
        Some(i) => (Some(text[..i].to_string()), &text[i + 1..]),
        None => (None, text),
    };
    let spans = ValueSpan::new(raw.span, &raw.text);
    let mut segments = Vec::new();
    for seg in path.split('/').filter(|s| !s.is_empty()) {
        if !encoded {
            segments.push(seg.to_string());
            continue;
        }
        match percent_decode(seg) {
            Ok(s) => segments.push(s),
            Err(bad) => {
                let at = spans.of(&raw.text, seg);
                let start = (at.start as usize + bad.offset).min(at.end as usize);
                let span = if spans.exact {
                    Span::new(at.file, start, (start + 3).min(at.end as usize).max(start))
                } else {
                    at
                };
                out.push(
                    Diagnostic::new(&CHECK, span, format!("bad percent escape in `{seg}`: {}", bad.reason))
                        .label("rrlib_uri cannot decode this path, so FINROC cannot connect this edge")
                        .help("write `%` as `%25`; version-1703 files percent-encode `<`, `>`, `[`, `]`, `%`"),
                );
                return None;
            }
        }
    }
    if segments.is_empty() {
        out.push(
            Diagnostic::new(&CHECK, raw.span, "this edge end names no port")
                .label("empty path")
                .help("write the port's path, e.g. `Element/Output/Port`"),
        );
        return None;
    }
    Some(EdgeEnd {
        absolute: path.starts_with('/'),
        scheme,
        segments,
        raw,
    })
}

/// `"Optional (2), Reconnect (1)"`: names with their index, as rrlib writes flag sets.
fn flags(value: &str, spans: ValueSpan, out: &mut Diagnostics) -> Vec<Flag> {
    let mut found = Vec::new();
    for item in comma_items(value) {
        let (name, index) = match item.split_once('(') {
            Some((n, rest)) => (
                n.trim(),
                rest.trim_end_matches(')').trim().parse::<u32>().ok(),
            ),
            None => (item, None),
        };
        let known = FLAGS
            .iter()
            .find(|(_, n, i)| n.eq_ignore_ascii_case(name) && index.is_none_or(|x| x == *i));
        match known {
            Some((f, _, _)) => found.push(*f),
            None => out.push(
                Diagnostic::new(&CHECK, spans.of(value, item), format!("`{item}` is not a connection flag"))
                    .label("FINROC cannot read these flags")
                    .help("the saved flags are `Reconnect (1)`, `Optional (2)`, `Scheduling Neutral (3)`, `Direction To Destination (4)`, `Direction To Source (5)`"),
            ),
        }
    }
    found
}

fn legacy_link(e: &Xml, out: &mut Diagnostics) -> Option<ParamLink> {
    let link = required(
        e,
        "link",
        "FINROC cannot tell which parameter this configures",
        out,
    )?;
    Some(ParamLink {
        path: link
            .text
            .split('/')
            .filter(|s| !s.is_empty())
            .map(str::to_string)
            .collect(),
        path_span: link.span,
        config: named_attr(e, "config"),
        cmdline: named_attr(e, "cmdline"),
        default: named_attr(e, "default"),
        legacy: true,
        span: e.span,
    })
}

/// `<parameter_links>`: `<element name>` nodes down to `<parameter name config cmdline>`.
fn link_tree(e: &Xml, path: &mut Vec<String>, links: &mut Vec<ParamLink>, out: &mut Diagnostics) {
    for c in &e.children {
        match c.name.as_str() {
            "element" => {
                let Some(name) = required(c, "name", "FINROC skips this branch", out) else {
                    continue;
                };
                path.push(name.text);
                link_tree(c, path, links, out);
                path.pop();
            }
            "parameter" => {
                let Some(name) = required(c, "name", "FINROC cannot match it to a parameter", out)
                else {
                    continue;
                };
                let mut full = path.clone();
                full.push(name.text);
                links.push(ParamLink {
                    path: full,
                    path_span: name.span,
                    config: named_attr(c, "config"),
                    cmdline: named_attr(c, "cmdline"),
                    default: named_attr(c, "default"),
                    legacy: false,
                    span: c.span,
                });
            }
            _ => unknown_tag(c, "<parameter_links>", out),
        }
    }
}
