//! The resolved model: the application as `ferroc check` sees it after resolution, as a
//! plain model file. Parameter values are looked up (config files, command line) and
//! written in each parameter's declared unit; group types and group ports are flattened
//! away, so every connection runs from a module output to a module input, with the
//! conversion steps of the path it replaces. Checking it plans the same application.

use super::text::{xml, xml_comment};
use ferroc_compiler::ir::{Application, ElementId, ElementKind, ModuleInstance, ParamSource, Wait};
use ferroc_compiler::library::LibrarySet;
use ferroc_compiler::plan::{module_edges, Plan, PlannedModule};
use ferroc_compiler::values::{parse_duration, parse_value, Value};

/// The resolved model's text. `manifests` maps a library name to the manifest path
/// written into `<use manifest>` (None for libraries built into ferroc).
pub fn document(
    app: &Application,
    libs: &LibrarySet,
    plan: &Plan,
    manifests: &[(String, Option<String>)],
    cmdline: &[(String, String)],
    model_file: &str,
    tool_version: &str,
) -> String {
    let mut out = String::new();
    out.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<!--\n");
    out.push_str(&format!(
        "  The resolved model of {}, written by ferroc {tool_version} (`ferroc bundle`).\n",
        xml_comment(model_file)
    ));
    out.push_str(
        "  Parameter values are looked up and written in each parameter's declared unit;\n  \
         group types and group ports are flattened away: every connection runs from a\n  \
         module output to a module input. `ferroc check` plans the same application.\n-->\n",
    );
    out.push_str(&format!(
        "<application name=\"{}\" version=\"1\">\n",
        xml(&app.name)
    ));
    for (name, manifest) in manifests {
        match manifest {
            Some(m) => out.push_str(&format!(
                "  <use library=\"{}\" manifest=\"{}\"/>\n",
                xml(name),
                xml(m)
            )),
            None => out.push_str(&format!("  <use library=\"{}\"/>\n", xml(name))),
        }
    }
    let mut children: Vec<Vec<ElementId>> = vec![Vec::new(); app.elements.len()];
    for (i, e) in app.elements.iter().enumerate() {
        if let Some(parent) = e.parent {
            children[parent.0 as usize].push(ElementId(i as u32));
        }
    }
    for &child in &children[0] {
        element(app, libs, plan, cmdline, &children, child, 1, &mut out);
    }
    connections(app, libs, &mut out);
    out.push_str("</application>\n");
    out
}

#[allow(clippy::too_many_arguments)]
fn element(
    app: &Application,
    libs: &LibrarySet,
    plan: &Plan,
    cmdline: &[(String, String)],
    children: &[Vec<ElementId>],
    id: ElementId,
    depth: usize,
    out: &mut String,
) {
    let e = app.element(id);
    let pad = "  ".repeat(depth);
    let name = xml(&e.name);
    let (open, tag) = match &e.kind {
        ElementKind::Application => return,
        ElementKind::Part { host } => {
            let host = host
                .as_ref()
                .map(|(h, _)| format!(" host=\"{}\"", xml(h)))
                .unwrap_or_default();
            (format!("<part name=\"{name}\"{host}"), "part")
        }
        ElementKind::Thread { .. } => {
            let attrs = thread_attributes(app, id, &e.kind);
            (format!("<thread name=\"{name}\"{attrs}"), "thread")
        }
        ElementKind::Group => (format!("<group name=\"{name}\""), "group"),
        ElementKind::Module(instance) => {
            if let Some(m) = plan.modules.iter().find(|m| m.element == id) {
                let lines = module_lines(libs, m, instance, cmdline, &pad);
                let open = format!(
                    "{pad}<module name=\"{name}\" type=\"{}\"",
                    xml(&m.type_name)
                );
                if lines.is_empty() {
                    out.push_str(&format!("{open}/>\n"));
                } else {
                    out.push_str(&format!("{open}>\n{}{pad}</module>\n", lines.concat()));
                }
            }
            return;
        }
    };
    let kids = &children[id.0 as usize];
    if kids.is_empty() {
        out.push_str(&format!("{pad}{open}/>\n"));
        return;
    }
    out.push_str(&format!("{pad}{open}>\n"));
    for &k in kids {
        element(app, libs, plan, cmdline, children, k, depth + 1, out);
    }
    out.push_str(&format!("{pad}</{tag}>\n"));
}

/// The attributes of a `<thread>` after its name: its trigger and timing.
fn thread_attributes(app: &Application, id: ElementId, kind: &ElementKind) -> String {
    let mut attrs = String::new();
    let ElementKind::Thread {
        period,
        pool,
        data_trigger,
        continuous,
        wait,
    } = kind
    else {
        return attrs;
    };
    if let Some(p) = period {
        attrs.push_str(&format!(" period=\"{}\"", duration_text(*p)));
    }
    if *data_trigger {
        attrs.push_str(" trigger=\"data\"");
    }
    if *continuous {
        attrs.push_str(" trigger=\"continuous\"");
    }
    if *wait != Wait::Park {
        attrs.push_str(&format!(" wait=\"{}\"", wait.as_str()));
    }
    if let Some(n) = pool {
        attrs.push_str(&format!(" pool=\"{n}\""));
    }
    if let Some((p, _)) = app.timing.priority.get(&id) {
        attrs.push_str(&format!(" priority=\"{p}\""));
    }
    if let Some((c, _)) = app.timing.cpu.get(&id) {
        attrs.push_str(&format!(" cpu=\"{c}\""));
    }
    attrs
}

/// The `<port>` and `<param>` lines inside a `<module>` (indented below `pad`).
fn module_lines(
    libs: &LibrarySet,
    m: &PlannedModule,
    instance: &ModuleInstance,
    cmdline: &[(String, String)],
    pad: &str,
) -> Vec<String> {
    let decl = libs.module_type(&m.type_name).map(|(_, t)| t);
    let mut lines = Vec::new();
    for g in &m.ports {
        let dir = match g.dir {
            ferroc_compiler::library::PortDir::In => "in",
            ferroc_compiler::library::PortDir::Out => "out",
        };
        let unit = g
            .unit
            .as_ref()
            .map_or(String::new(), |u| format!(" unit=\"{}\"", xml(u)));
        let count = g.count.map_or(String::new(), |n| format!(" count=\"{n}\""));
        lines.push(format!(
            "{pad}  <port name=\"{}\" dir=\"{dir}\" type=\"{}\"{unit}{count}/>\n",
            xml(&g.name),
            xml(&g.ty)
        ));
    }
    for (param, value) in &m.params {
        // The source text (as looked up) when no normalised text reads back exactly.
        let source = || {
            let p = instance.params.iter().find(|p| p.name == *param)?;
            match (p.from_cmdline(cmdline), &p.source) {
                (Some(v), _) => Some(v.to_string()),
                (None, ParamSource::Cmdline) => None,
                (None, _) => Some(p.text.clone()),
            }
        };
        let text = decl
            .and_then(|t| t.param(param))
            .and_then(|d| value_text(value, &d.ty, d.unit.as_ref()))
            .or_else(source);
        let Some(text) = text else {
            continue;
        };
        lines.push(format!(
            "{pad}  <param name=\"{}\">{}</param>\n",
            xml(param),
            xml(&text)
        ));
    }
    lines
}

/// The transport settings of a connection between parts: those of the first hop that
/// has any (what the plan's link takes), durations written back exactly in seconds.
fn sharing(app: &Application, hops: &[usize]) -> String {
    let Some(c) = hops.iter().map(|&h| &app.connections[h]).find(|c| {
        c.sharing().is_some() || c.min_interval_seconds().is_some() || c.period_seconds().is_some()
    }) else {
        return String::new();
    };
    let mut attrs = String::new();
    if let Some((mode, _)) = c.sharing() {
        attrs.push_str(&format!(" sharing=\"{}\"", xml(mode)));
    }
    if let Some(s) = c.min_interval_seconds() {
        attrs.push_str(&format!(" min-interval=\"{s}s\""));
    }
    if let Some(s) = c.period_seconds() {
        attrs.push_str(&format!(" period=\"{s}s\""));
    }
    attrs
}

/// Module-to-module connections, found the way the plan finds them, each with the
/// conversion steps of every hop it replaces (so scales combine in the same order).
fn connections(app: &Application, libs: &LibrarySet, out: &mut String) {
    for (edge, from, to) in module_edges(app, libs) {
        let mut attrs = format!(
            "from=\"{}/{}\" to=\"{}/{}\"",
            xml(&app.path(edge.from_module)),
            xml(from.name),
            xml(&app.path(edge.to_module)),
            xml(to.name)
        );
        if let Some(c) = edge
            .hops
            .iter()
            .map(|&h| &app.connections[h])
            .find(|c| c.queue.is_some())
        {
            attrs.push_str(&format!(" queue=\"{}\"", c.queue.unwrap_or(1)));
            if let Some(policy) = &c.on_full {
                attrs.push_str(&format!(" on-full=\"{}\"", xml(policy)));
            }
        }
        if edge.delayed {
            attrs.push_str(" delay=\"1\"");
        }
        if app.element(edge.from_module).part != app.element(edge.to_module).part {
            attrs.push_str(&sharing(app, &edge.hops));
            // The first hop with `reliability=` decides the link's QoS, as in the plan.
            let reliable = edge
                .hops
                .iter()
                .find_map(|&h| app.connections[h].reliable());
            if let Some(reliable) = reliable {
                let value = if reliable { "reliable" } else { "best-effort" };
                attrs.push_str(&format!(" reliability=\"{value}\""));
            }
            let deadline = (edge.hops.iter()).find_map(|&h| app.connections[h].deadline_seconds());
            if let Some(s) = deadline {
                attrs.push_str(&format!(" deadline=\"{s}s\""));
            }
        }
        let mut steps = String::new();
        for &h in &edge.hops {
            let c = &app.connections[h];
            // Parts taken out of the value, in the plan's order: `port[i]`, then each
            // step's index and field (the scales below combine independently).
            if let Some(i) = c.from_index {
                steps.push_str(&format!("    <convert index=\"{i}\"/>\n"));
            }
            for step in &c.converts {
                if let Some((i, _)) = step.index {
                    steps.push_str(&format!("    <convert index=\"{i}\"/>\n"));
                }
                if let Some((f, _)) = &step.field {
                    steps.push_str(&format!("    <convert field=\"{}\"/>\n", xml(f)));
                }
            }
            for step in &c.converts {
                let mut s = String::new();
                if let Some((t, _)) = &step.to_type {
                    s.push_str(&format!(" to-type=\"{}\"", xml(&t.to_string())));
                }
                if let Some((x, _)) = step.scale {
                    s.push_str(&format!(" scale=\"{x:?}\""));
                }
                if let Some((x, _)) = step.offset {
                    s.push_str(&format!(" offset=\"{x:?}\""));
                }
                if !s.is_empty() {
                    steps.push_str(&format!("    <convert{s}/>\n"));
                }
            }
        }
        if steps.is_empty() {
            out.push_str(&format!("  <connect {attrs}/>\n"));
        } else {
            out.push_str(&format!("  <connect {attrs}>\n{steps}  </connect>\n"));
        }
    }
}

/// A duration text that parses back to exactly `seconds`.
fn duration_text(seconds: f64) -> String {
    let ms = seconds * 1000.0;
    let candidates = [
        format!("{}ms", ms.round()),
        format!("{seconds:?}s"),
        format!("{ms:?}ms"),
    ];
    for c in &candidates {
        if parse_duration(c).is_ok_and(|s| s == seconds) {
            return c.clone();
        }
    }
    candidates[1].clone()
}

/// A text for `value` that parses back to exactly `value` (in the declared unit when
/// it reads back exactly, else a bare number, which means the declared unit).
fn value_text(
    value: &Value,
    ty: &ferroc_compiler::types::Type,
    unit: Option<&ferroc_compiler::units::Unit>,
) -> Option<String> {
    let bare = bare_text(value);
    let mut candidates = Vec::new();
    if let (Some(u), Value::Float(_) | Value::List(_)) = (unit, value) {
        candidates.push(format!("{bare} {u}"));
    }
    candidates.push(bare);
    candidates
        .into_iter()
        .find(|c| parse_value(c, ty, unit).is_ok_and(|v| v == *value))
}

fn bare_text(value: &Value) -> String {
    match value {
        Value::Bool(b) => b.to_string(),
        Value::Int(i) => i.to_string(),
        Value::Float(x) => format!("{x:?}"),
        Value::Str(s) | Value::Opaque(s) => s.clone(),
        Value::Duration(s) => duration_text(*s),
        Value::List(items) => items.iter().map(bare_text).collect::<Vec<_>>().join(", "),
    }
}
