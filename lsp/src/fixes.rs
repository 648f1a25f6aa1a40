//! The mechanical fixes of findings beyond "did you mean": each is the edit a `help:`
//! line asks for, made by the model-text edit code `ferroc inspect --edit` uses
//! (`ferroc_compiler::edit`), so layout and comments stay.
//!
//! - a connection setting the help names, on the `<connect>` the finding points into:
//!   `delay="1"` (S101), `initial="1"` (D115 and the empty-queue rings),
//!   `on-full="drop-oldest"` (D107, D105; only on a connection with a queue);
//! - T109: a `<connect>` to the unconnected required input from each output of the
//!   same type and a unit of the same dimension, best first (the same unit, then the
//!   same thread container, then the same part);
//! - T112: the `scale` the units make redundant goes (its `<convert>` too when that
//!   was all it said, `edit::set_attribute`);
//! - T101, S106: `from` and `to` swapped.

use crate::navigate::covers;
use ferroc_compiler::diagnostic::Diagnostic;
use ferroc_compiler::edit::{self, Op};
use ferroc_compiler::ir::{Application, ElementId, Endpoint};
use ferroc_compiler::library::{LibrarySet, PortDir};
use ferroc_compiler::units::{relate, UnitRelation};
use ferroc_compiler::CheckResult;

/// One fix: what it does, and the whole text after it.
pub struct Fix {
    pub title: String,
    pub text: String,
    /// The one obvious fix (the client may apply it with a single key).
    pub preferred: bool,
}

/// At most this many connections are offered for one unconnected input.
const MAX_SOURCES: usize = 5;

/// The connection settings a help may name, and the edit that writes them.
const SETTINGS: [(&str, &str); 3] = [("delay", "1"), ("initial", "1"), ("on-full", "drop-oldest")];

/// The fixes for finding `d` in `text`, the current text of the file it points into.
pub fn fixes(d: &Diagnostic, result: &CheckResult, text: &str) -> Vec<Fix> {
    let help = d.help.as_deref().unwrap_or_default();
    let at = d.primary.span.start as usize;
    let mut out = Vec::new();
    for (name, value) in SETTINGS {
        if help.contains(&format!("{name}=\"{value}\"")) && setting_fits(d, result, name) {
            let edited = edit::set_attribute(text, "connect", at, name, Some(value));
            push(
                &mut out,
                d,
                format!("set {name}=\"{value}\" on this <connect>"),
                edited,
            );
        }
    }
    match d.code() {
        "T109" => out.extend(connect_required_input(d, result, text)),
        "T112" if help.starts_with("remove `scale`") => {
            let edited = edit::set_attribute(text, "convert", at, "scale", None);
            push(&mut out, d, "remove `scale`".into(), edited);
        }
        "T101" | "S106" if help.contains("swap `from` and `to`") => {
            let tag = if d.code() == "T101" {
                "connect"
            } else {
                "flow"
            };
            let edited = edit::swap_attributes(text, tag, at, "from", "to");
            push(&mut out, d, "swap `from` and `to`".into(), edited);
        }
        _ => {}
    }
    if let [one] = out.as_mut_slice() {
        one.preferred = true;
    }
    out
}

fn push(out: &mut Vec<Fix>, d: &Diagnostic, what: String, edited: Result<String, String>) {
    if let Ok(text) = edited {
        out.push(Fix {
            title: format!("{}: {what}", d.code()),
            text,
            preferred: false,
        });
    }
}

/// Whether the connection the finding points into takes the setting: `on-full` only
/// where a queue is (on a plain connection it means nothing).
fn setting_fits(d: &Diagnostic, result: &CheckResult, name: &str) -> bool {
    if name != "on-full" {
        return true;
    }
    let Some(app) = &result.app else { return false };
    let here = d.primary.span;
    app.connections.iter().any(|c| {
        (covers(c.span, here) || covers(c.from_span, here) || covers(c.to_span, here))
            && c.queue.is_some()
    })
}

/// T109: one `<connect>` per compatible output, best first.
fn connect_required_input(d: &Diagnostic, result: &CheckResult, text: &str) -> Vec<Fix> {
    let Some(app) = &result.app else {
        return Vec::new();
    };
    // Only an instance written in this model file (not in a fragment or group type):
    // the `<connect>` goes into the model's own text.
    if d.primary.span.file != app.span.file {
        return Vec::new();
    }
    let Some((id, _)) = app.modules().find(|(id, _)| {
        let e = app.element(*id);
        e.name_span == d.primary.span && e.instantiated_at.is_none()
    }) else {
        return Vec::new();
    };
    let libs = &result.libraries;
    let mut out = Vec::new();
    for (port, decl) in app.module_ports(libs, id) {
        let input = Endpoint::Port { element: id, port };
        let unconnected = app.incoming(input).next().is_none() && !app.cut_off.contains(&input);
        if !decl.required || decl.dir != PortDir::In || !unconnected {
            continue;
        }
        let to = format!("{}/{}", app.path(id), decl.name);
        for from in sources(app, libs, id, input) {
            let ops = [Op::Connect {
                from: from.clone(),
                to: to.clone(),
            }];
            if let Ok(edited) = edit::apply(text, &ops) {
                out.push(Fix {
                    title: format!("{}: connect `{from}` → `{to}`", d.code()),
                    text: edited.text,
                    preferred: false,
                });
            }
        }
    }
    out
}

/// The outputs of other modules that can feed `input`: the same type, a unit of the
/// same dimension (or none on both), best first.
fn sources(app: &Application, libs: &LibrarySet, id: ElementId, input: Endpoint) -> Vec<String> {
    let Some(want) = app.view(libs, input) else {
        return Vec::new();
    };
    let here = app.element(id);
    let mut found: Vec<(u8, String)> = Vec::new();
    for (other, _) in app.modules().filter(|(m, _)| *m != id) {
        for (port, decl) in app.module_ports(libs, other) {
            if decl.dir != PortDir::Out {
                continue;
            }
            let ep = Endpoint::Port {
                element: other,
                port,
            };
            let Some(view) = app.view(libs, ep) else {
                continue;
            };
            let same_unit = match (view.unit, want.unit) {
                (None, None) => true,
                (Some(a), Some(b)) => match relate(a, b) {
                    UnitRelation::Same => true,
                    UnitRelation::Scaled(_) => false,
                    UnitRelation::DifferentDimension => continue,
                },
                _ => continue,
            };
            if view.ty != want.ty {
                continue;
            }
            let there = app.element(other);
            let rank = u8::from(!same_unit) * 4
                + u8::from(there.thread != here.thread) * 2
                + u8::from(there.part != here.part);
            found.push((rank, format!("{}/{}", app.path(other), decl.name)));
        }
    }
    found.sort();
    found
        .into_iter()
        .take(MAX_SOURCES)
        .map(|(_, p)| p)
        .collect()
}
