//! `ferroc graph`: the application as a Graphviz DOT graph, drawn the way iB2C users draw
//! behaviour networks.
//!
//! Behaviours are boxes with their meta inputs on top (`s` stimulation, `i0…` inhibition,
//! `ch k` fusion channels) and their meta outputs below (`a` activity, derived activities,
//! `r` target rating). Stimulation edges are green arrows, inhibition edges red bars,
//! activities and target ratings into a fusion channel blue dashed arrows, data grey.
//! Parts and groups are clusters (an iB2C group says so); thread containers are left out.
//! Edges run from module to module, through group ports (`schedule::flow`).

use ferroc_model::ir::{Application, ElementId, ElementKind, Endpoint};
use ferroc_model::library::module_type::ModuleKind;
use ferroc_model::library::{LibrarySet, PortRole};
use ferroc_schedule::data_edges;
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;

/// What the receiving end of an edge is.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Head {
    Stimulation,
    Inhibition(u32),
    /// Activity or target rating into fusion channel k.
    ChannelMeta(u32),
    /// Data into fusion channel k.
    ChannelData(u32),
    Data,
}

/// The DOT text of an application.
pub fn dot(app: &Application, libs: &LibrarySet) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "digraph {} {{", quote(&app.name));
    out.push_str(
        "  rankdir=TB;\n  newrank=true;\n  labelloc=b;\n  fontname=\"Helvetica\";\n  \
         node [fontname=\"Helvetica\", fontsize=10];\n  \
         edge [fontname=\"Helvetica\", fontsize=9];\n",
    );
    let _ = writeln!(
        out,
        "  label={};",
        quote(&format!(
            "{} — stimulation: green arrow · inhibition: red bar · activity / target rating \
             into a fusion channel: blue dashed · data: grey",
            app.name
        ))
    );
    // Clusters: parts and groups; modules sit in the nearest one (threads are skipped).
    let mut children: BTreeMap<Option<ElementId>, Vec<ElementId>> = BTreeMap::new();
    for (i, e) in app.elements.iter().enumerate() {
        let id = ElementId(i as u32);
        let shown = matches!(
            e.kind,
            ElementKind::Part { .. } | ElementKind::Group | ElementKind::Module(_)
        );
        if shown {
            children.entry(cluster_of(app, id)).or_default().push(id);
        }
    }
    let ib2c: BTreeSet<ElementId> = app
        .modules()
        .filter(|(_, m)| m.characteristic().is_some())
        .filter_map(|(id, _)| app.enclosing_group(id))
        .collect();
    emit_level(app, libs, &children, &ib2c, None, 1, &mut out);
    for line in edges(app, libs) {
        out.push_str(&line);
    }
    out.push_str("}\n");
    out
}

/// The nearest part or group above an element.
fn cluster_of(app: &Application, id: ElementId) -> Option<ElementId> {
    let mut cur = app.element(id).parent;
    while let Some(c) = cur {
        if matches!(
            app.element(c).kind,
            ElementKind::Part { .. } | ElementKind::Group
        ) {
            return Some(c);
        }
        cur = app.element(c).parent;
    }
    None
}

fn emit_level(
    app: &Application,
    libs: &LibrarySet,
    children: &BTreeMap<Option<ElementId>, Vec<ElementId>>,
    ib2c: &BTreeSet<ElementId>,
    parent: Option<ElementId>,
    depth: usize,
    out: &mut String,
) {
    let pad = "  ".repeat(depth);
    for &id in children.get(&parent).map(Vec::as_slice).unwrap_or(&[]) {
        let e = app.element(id);
        match &e.kind {
            ElementKind::Module(_) => {
                let _ = writeln!(out, "{pad}{}", node(app, libs, id));
            }
            kind => {
                let label = match kind {
                    ElementKind::Part {
                        host: Some((host, _)),
                    } => format!("part {} ({host})", e.name),
                    ElementKind::Part { .. } => format!("part {}", e.name),
                    _ if ib2c.contains(&id) => format!("{} (iB2C group)", e.name),
                    _ => e.name.clone(),
                };
                let style = if ib2c.contains(&id) {
                    "style=\"rounded,bold\"; color=\"#1565c0\""
                } else if matches!(kind, ElementKind::Part { .. }) {
                    "style=dashed; color=\"#9e9e9e\""
                } else {
                    "style=rounded; color=\"#616161\""
                };
                let _ = writeln!(out, "{pad}subgraph cluster_{} {{", id.0);
                let _ = writeln!(out, "{pad}  label={}; {style};", quote(&label));
                emit_level(app, libs, children, ib2c, Some(id), depth + 1, out);
                let _ = writeln!(out, "{pad}}}");
            }
        }
    }
}

/// A module: a plain box, or a behaviour with its meta ports as record fields.
fn node(app: &Application, libs: &LibrarySet, id: ElementId) -> String {
    let e = app.element(id);
    let Some(mt) = app.module_type(libs, id) else {
        return format!("m{} [shape=box, label={}];", id.0, quote(&e.name));
    };
    if !mt.is_behaviour() {
        return format!(
            "m{} [shape=box, style=rounded, label={}];",
            id.0,
            quote(&format!("{}\n{}", e.name, mt.qualified))
        );
    }
    let mut inputs = vec!["<s> s".to_string()];
    let mut channels = BTreeSet::new();
    for (_, p) in app.module_ports(libs, id) {
        if let Some(k) = p.name.strip_prefix("inhibition/") {
            inputs.push(format!("<i{k}> i{k}"));
        } else if let Some(k) = channel_of(&p.name) {
            channels.insert(k);
        }
    }
    inputs.extend(channels.iter().map(|k| format!("<c{k}> ch {k}")));
    let mut outputs = vec!["<a> a".to_string()];
    outputs.extend(
        mt.derived_activities
            .iter()
            .enumerate()
            .map(|(i, d)| format!("<d{i}> a/{}", record_text(d))),
    );
    outputs.push("<r> r".to_string());
    let kind = if mt.kind == ModuleKind::Fusion {
        "fusion"
    } else {
        "behaviour"
    };
    let title = format!(
        "{}\\n{}",
        record_text(&e.name),
        record_text(&format!("{} ({kind})", mt.qualified))
    );
    let label = format!(
        "{{{{{}}}|{title}|{{{}}}}}",
        inputs.join("|"),
        outputs.join("|")
    );
    let bold = match &e.kind {
        ElementKind::Module(m) if m.characteristic().is_some() => ", penwidth=2",
        _ => "",
    };
    format!(
        "m{} [shape=record, style=filled, fillcolor=\"#fff8e1\"{bold}, label=\"{label}\"];",
        id.0
    )
}

/// `in/k/…` → k.
fn channel_of(name: &str) -> Option<u32> {
    name.strip_prefix("in/")?.split_once('/')?.0.parse().ok()
}

/// The edges, one per (source port, destination port), in a stable order.
fn edges(app: &Application, libs: &LibrarySet) -> Vec<String> {
    let mut seen = BTreeSet::new();
    let mut lines = BTreeMap::new();
    for e in data_edges(app, libs) {
        let (Some(&first), Some(&last)) = (e.hops.first(), e.hops.last()) else {
            continue;
        };
        let (from, to) = (app.connections[first].from, app.connections[last].to);
        if !seen.insert((from, to)) {
            continue;
        }
        let (Some(fv), Some(tv)) = (app.view(libs, from), app.view(libs, to)) else {
            continue;
        };
        let to_behaviour = app
            .module_type(libs, e.to_module)
            .is_some_and(|t| t.is_behaviour());
        let head = match (tv.role, tv.name) {
            (_, _) if !to_behaviour => Head::Data,
            (PortRole::Meta, "stimulation") => Head::Stimulation,
            (PortRole::Meta, n) if n.starts_with("inhibition/") => {
                Head::Inhibition(n["inhibition/".len()..].parse().unwrap_or(0))
            }
            (PortRole::Meta, n) => channel_of(n).map_or(Head::Data, Head::ChannelMeta),
            (_, n) => channel_of(n).map_or(Head::Data, Head::ChannelData),
        };
        let tail = tail_port(app, libs, from, fv.name, fv.role);
        let head_port = match head {
            Head::Stimulation => ":s:n".to_string(),
            Head::Inhibition(k) => format!(":i{k}:n"),
            Head::ChannelMeta(k) | Head::ChannelData(k) => format!(":c{k}:n"),
            Head::Data => String::new(),
        };
        let style = match head {
            Head::Stimulation => "color=\"#2e7d32\", penwidth=1.6, arrowhead=normal".to_string(),
            Head::Inhibition(_) => "color=\"#c62828\", penwidth=1.6, arrowhead=tee".to_string(),
            Head::ChannelMeta(_) => "color=\"#1565c0\", style=dashed, arrowhead=empty".to_string(),
            Head::ChannelData(_) | Head::Data => format!(
                "color=\"#757575\", fontcolor=\"#757575\", label={}{}",
                quote(fv.name),
                if e.delayed { ", style=dotted" } else { "" }
            ),
        };
        let line = format!(
            "  m{}{tail} -> m{}{head_port} [{style}];\n",
            from.element().0,
            to.element().0
        );
        lines.insert((head, from, to), line);
    }
    lines.into_values().collect()
}

/// The record field an edge leaves from: a behaviour's activity, derived activity or
/// target rating.
fn tail_port(
    app: &Application,
    libs: &LibrarySet,
    from: Endpoint,
    name: &str,
    role: PortRole,
) -> String {
    let Some(mt) = app.module_type(libs, from.element()) else {
        return String::new();
    };
    if !mt.is_behaviour() || role != PortRole::Meta {
        return String::new();
    }
    match name {
        "activity" => ":a:s".to_string(),
        "target_rating" => ":r:s".to_string(),
        n => n
            .strip_prefix("activity/")
            .and_then(|d| mt.derived_activities.iter().position(|x| x == d))
            .map_or(String::new(), |i| format!(":d{i}:s")),
    }
}

/// A DOT string literal (`\n` in `text` stays a line break).
fn quote(text: &str) -> String {
    let mut s = String::with_capacity(text.len() + 2);
    s.push('"');
    for c in text.chars() {
        match c {
            '"' => s.push_str("\\\""),
            '\\' => s.push_str("\\\\"),
            '\n' => s.push_str("\\n"),
            c => s.push(c),
        }
    }
    s.push('"');
    s
}

/// Text inside a record field: the record syntax characters escaped.
fn record_text(text: &str) -> String {
    let mut s = String::with_capacity(text.len());
    for c in text.chars() {
        if matches!(c, '{' | '}' | '|' | '<' | '>' | '"' | '\\') {
            s.push('\\');
        }
        s.push(c);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quoting_and_record_escapes() {
        assert_eq!(quote("a\"b\\c\nd"), "\"a\\\"b\\\\c\\nd\"");
        assert_eq!(record_text("a|b{c}<d>"), "a\\|b\\{c\\}\\<d\\>");
        assert_eq!(channel_of("in/3/linear"), Some(3));
        assert_eq!(channel_of("inhibition/0"), None);
    }
}
