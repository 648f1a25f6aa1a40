//! Hover: a connection end's port (type, unit, direction, writer and readers); a
//! parameter (type, unit, range, default, choices, the value the model resolves and
//! the quantity it reads: `3.6 km/h` = `1 m/s`);
//! a module type; the explanation of a finding's check.

use crate::navigate::covers;
use crate::request::{self, Reply};
use crate::server::Server;
use ferroc_compiler::diagnostic::Diagnostic;
use ferroc_compiler::ir::{Application, ElementId, ElementKind, Endpoint, ParamSource};
use ferroc_compiler::library::{LibrarySet, ParamDecl, PortDir};
use ferroc_compiler::source::Span;
use ferroc_compiler::types::Type;
use ferroc_compiler::CheckResult;
use lsp_server::Request;
use lsp_types::{Hover, HoverContents, HoverParams, MarkupContent, MarkupKind};

pub fn hover(server: &Server, req: &Request) -> Reply {
    let p: HoverParams = request::params(req)?;
    let (result, here) = match request::checked_at(server, &p.text_document_position_params) {
        Ok(found) => found,
        Err(reply) => return reply,
    };
    let mut parts = Vec::new();
    if let Some(app) = &result.app {
        parts.extend(port_text(app, &result.libraries, here));
        parts.extend(param_text(app, &result.libraries, here));
        parts.extend(module_type_text(app, &result.libraries, here));
        parts.extend(thread_text(app, &result.libraries, here));
    }
    parts.extend(findings_text(&result, here));
    if parts.is_empty() {
        return Ok(Some(serde_json::Value::Null));
    }
    let hover = Hover {
        contents: HoverContents::Markup(MarkupContent {
            kind: MarkupKind::Markdown,
            value: parts.join("\n\n---\n\n"),
        }),
        range: None,
    };
    Ok(Some(serde_json::to_value(hover).unwrap_or_default()))
}

fn port_text(app: &Application, libs: &LibrarySet, here: Span) -> Option<String> {
    let c = app
        .connections
        .iter()
        .find(|c| covers(c.from_span, here) || covers(c.to_span, here))?;
    let end = if covers(c.from_span, here) {
        c.from
    } else {
        c.to
    };
    Some(describe_port(app, libs, end))
}

/// `port robot/control/avoid/activity: out f64 [m/s]`, its writers and readers.
pub fn describe_port(app: &Application, libs: &LibrarySet, end: Endpoint) -> String {
    let path = format!(
        "{}/{}",
        app.path(end.element()),
        app.view(libs, end).map_or("", |v| v.name)
    );
    let Some(view) = app.view(libs, end) else {
        return format!("`{path}`");
    };
    let dir = match view.dir {
        PortDir::In => "input",
        PortDir::Out => "output",
    };
    let unit = view.unit.map(|u| format!(" in `{u}`")).unwrap_or_default();
    let mut text = format!("**{dir}** `{path}`: `{}`{unit}", view.ty);
    if view.required {
        text.push_str(" (required)");
    }
    let writers: Vec<String> = app
        .incoming(end)
        .map(|c| end_path(app, libs, c.from))
        .collect();
    let readers: Vec<String> = (app.connections.iter())
        .filter(|c| c.from == end)
        .map(|c| end_path(app, libs, c.to))
        .collect();
    if !writers.is_empty() {
        text.push_str(&format!("\n\nwritten by: `{}`", writers.join("`, `")));
    }
    if !readers.is_empty() {
        text.push_str(&format!("\n\nread by: `{}`", readers.join("`, `")));
    }
    text
}

fn end_path(app: &Application, libs: &LibrarySet, end: Endpoint) -> String {
    let name = app.view(libs, end).map_or("?", |v| v.name);
    format!("{}/{name}", app.path(end.element()))
}

fn param_text(app: &Application, libs: &LibrarySet, here: Span) -> Option<String> {
    for (id, m) in app.modules() {
        for value in &m.params {
            if !(covers(value.name_span, here) || covers(value.span, here)) {
                continue;
            }
            let ty = app.module_type(libs, id)?;
            let decl = ty.param(&value.name)?;
            let mut text = format!(
                "**parameter** `{}/{}`: `{}`",
                app.path(id),
                decl.name,
                decl.ty
            );
            if let Some(u) = &decl.unit {
                text.push_str(&format!(" in `{u}`"));
            }
            match (decl.min, decl.max) {
                (Some(lo), Some(hi)) => text.push_str(&format!("\n\nrange: {lo} … {hi}")),
                (Some(lo), None) => text.push_str(&format!("\n\nat least {lo}")),
                (None, Some(hi)) => text.push_str(&format!("\n\nat most {hi}")),
                (None, None) => {}
            }
            if let Some(doc) = param_doc(libs, decl) {
                text.push_str(&format!("\n\n{doc}"));
            }
            if let Some(d) = &decl.default {
                text.push_str(&format!("\n\ndefault: `{d}`"));
            }
            if !decl.choices.is_empty() {
                text.push_str(&format!("\n\none of: `{}`", decl.choices.join("`, `")));
            }
            let source = match &value.source {
                ParamSource::Inline => "written here".to_string(),
                ParamSource::Config(Ok(_)) => "from its config file".to_string(),
                ParamSource::Config(Err(why)) => format!("config entry missing: {why}"),
                ParamSource::Cmdline => "given on the command line (`--param`)".to_string(),
            };
            text.push_str(&format!("\n\nvalue: `{}` ({source})", value.text));
            let written = match &value.source {
                ParamSource::Config(Ok((t, _))) => Some(t.as_str()),
                ParamSource::Inline => Some(value.text.as_str()),
                _ => None,
            };
            if let Some(q) = written.and_then(|w| quantity(decl, w)) {
                text.push_str(&format!("\n\n{q}"));
            }
            if let Some((name, _)) = &value.cmdline {
                text.push_str(&format!(
                    "; `--param {name}=VALUE` at start-up overrides it"
                ));
            }
            return Some(text);
        }
    }
    None
}

/// A numeric value as the compiler reads it: its number and unit, and what that is in
/// the parameter's unit (`3.6 km/h` → `1 m/s`); why it cannot be read, when it cannot.
fn quantity(decl: &ParamDecl, written: &str) -> Option<String> {
    use ferroc_compiler::values::{parse_value, split_number, Value};
    let (number, unit) = split_number(written);
    if number.is_empty() {
        return None;
    }
    let declared = match (&decl.unit, &decl.ty) {
        (Some(u), _) => u.to_string(),
        (None, Type::Duration) => "s".to_string(),
        (None, _) => String::new(),
    };
    let n = match parse_value(written, &decl.ty, decl.unit.as_ref()) {
        Ok(Value::Int(i)) => i as f64,
        Ok(Value::Float(f) | Value::Duration(f)) => f,
        Ok(_) => return None,
        Err(e) => return Some(format!("quantity: cannot be read: {}", value_error(&e))),
    };
    let read = format!("{} {declared}", short(n));
    let read = read.trim_end();
    Some(match (unit.is_empty(), declared.is_empty()) {
        (true, false) => format!("quantity: `{number}` has no unit: read as `{read}`"),
        (true, true) => format!("quantity: `{number}` (the parameter has no unit)"),
        (false, _) => format!("quantity: `{number}` `{unit}` = `{read}` in the parameter's unit"),
    })
}

fn value_error(e: &ferroc_compiler::values::ValueError) -> &str {
    match e {
        ferroc_compiler::values::ValueError::Syntax(m)
        | ferroc_compiler::values::ValueError::WrongDimension(m) => m,
    }
}

/// A number with at most six decimals and no trailing zeros.
fn short(n: f64) -> String {
    let s = format!("{n:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    match s {
        "-0" => "0".to_string(),
        s => s.to_string(),
    }
}

fn module_type_text(app: &Application, libs: &LibrarySet, here: Span) -> Option<String> {
    let (_, m) = app.modules().find(|(_, m)| covers(m.type_span, here))?;
    let ty = &libs.get(m.library).module_types[m.type_index];
    let mut text = format!("**module type** `{}`", ty.qualified);
    for p in &ty.ports {
        let dir = match p.dir {
            PortDir::In => "in ",
            PortDir::Out => "out",
        };
        let unit = p
            .unit
            .as_ref()
            .map(|u| format!(" [{u}]"))
            .unwrap_or_default();
        text.push_str(&format!("\n- {dir} `{}`{unit}", p.name));
    }
    for p in &ty.params {
        text.push_str(&format!("\n- param `{}`", p.name));
    }
    Some(text)
}

/// The `doc` of a parameter's declaration in its manifest.
fn param_doc(libs: &LibrarySet, decl: &ferroc_compiler::library::ParamDecl) -> Option<String> {
    let lib = libs.libraries.iter().find(|l| l.file == decl.span.file)?;
    let mut found = None;
    crate::navigate::walk(lib.root(), &mut |e| {
        if found.is_none() && e.name.as_str() == "param" && e.value_span("name") == decl.span {
            found = e.value("doc").map(str::to_string);
        }
    });
    found
}

/// A thread container's name: its period or trigger, how many modules it runs, and
/// its load from the declared budgets (the figure S102/S103 judge).
fn thread_text(app: &Application, libs: &LibrarySet, here: Span) -> Option<String> {
    let (i, e) =
        app.elements.iter().enumerate().find(|(_, e)| {
            matches!(e.kind, ElementKind::Thread { .. }) && covers(e.name_span, here)
        })?;
    let ElementKind::Thread {
        period,
        data_trigger,
        continuous,
        pool,
        ..
    } = &e.kind
    else {
        return None;
    };
    let id = ElementId(i as u32);
    let how = match (period, data_trigger, continuous) {
        (_, true, _) => "runs when data arrives".to_string(),
        (_, _, true) => "runs continuously".to_string(),
        (Some(p), _, _) => format!("runs every {} ms", p * 1000.0),
        (None, _, _) => "has no period".to_string(),
    };
    let modules = app
        .modules()
        .filter(|(m, _)| app.element(*m).thread == Some(id))
        .count();
    let pool = pool
        .map(|n| format!(", a pool of {n} workers"))
        .unwrap_or_default();
    let mut text = format!(
        "**thread container** `{}` {how}{pool}; {modules} module(s)",
        app.path(id)
    );
    use ferroc_compiler::checks::scheduling;
    match scheduling::loads(app, libs, None)
        .into_iter()
        .find(|l| l.thread == id)
    {
        Some(load) => {
            let total = scheduling::duration(load.total());
            let with = load.budgets.len();
            text.push_str(&format!(
                "\n\nload: {total} per cycle from the budgets of {with} module(s)"
            ));
            if load.unbudgeted > 0 {
                text.push_str(&format!(" ({} without a budget)", load.unbudgeted));
            }
            if let Some(u) = load.utilisation() {
                text.push_str(&format!(", {} of the period", scheduling::percent(u)));
            }
        }
        None => text.push_str("\n\nload: unknown (no module it runs declares a `budget`)"),
    }
    Some(text)
}

/// The findings at the cursor with their check's explanation (`ferroc explain`).
fn findings_text(result: &CheckResult, here: Span) -> Vec<String> {
    let mut seen = Vec::new();
    result
        .diagnostics
        .iter()
        .filter(|d| covers(d.primary.span, here))
        .filter(|d| {
            let new = !seen.contains(&d.code());
            seen.push(d.code());
            new
        })
        .map(explain)
        .collect()
}

pub fn explain(d: &Diagnostic) -> String {
    let c = d.check;
    format!(
        "**{} {}** ({})\n\n{}\n\n{}",
        c.code,
        c.name,
        c.severity.as_str(),
        c.summary,
        c.explanation
    )
}
