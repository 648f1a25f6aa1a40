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
//! - T101, S106: `from` and `to` swapped;
//! - L104: the `<use library manifest>` the file lacks, after its other `<use>`s;
//! - P110, X103: the value the help writes (`0.4 m`, the host's first spelling);
//! - B103, B108: the parameter the help offers to set (`stimulation_mode` `enabled`,
//!   the number of channels), by the edit code's `set` operation.

use crate::navigate::covers;
use ferroc_compiler::diagnostic::Diagnostic;
use ferroc_compiler::edit::{self, Op};
use ferroc_compiler::ir::{Application, ElementId, Endpoint};
use ferroc_compiler::library::{LibrarySet, PortDir};
use ferroc_compiler::units::{relate, UnitRelation};
use ferroc_compiler::CheckResult;
use std::path::{Path, PathBuf};

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
        "L104" => out.extend(use_library(d, result, text)),
        _ => {}
    }
    out.extend(rewrite(d, text));
    out.extend(set_param(d, result, text));
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

/// L104 "add <use library="lib"/>": into the file the finding is in, after its other
/// `<use>`s, naming the manifest the library was loaded from (relative to the file's
/// folder) so that the `<use>` finds the same one.
fn use_library(d: &Diagnostic, result: &CheckResult, text: &str) -> Option<Fix> {
    let help = d.help.as_deref()?;
    let rest = help.strip_prefix("add <use library=\"")?;
    let name = &rest[..rest.find('"')?];
    let lib = result.libraries.get(*result.libraries.by_name.get(name)?);
    let file = &result.sources.get(d.primary.span.file).path;
    let snippet = match (lib.path.is_absolute(), file.parent()) {
        (true, Some(dir)) => format!(
            "<use library=\"{name}\" manifest=\"{}\"/>",
            relative(&lib.path, dir).display()
        ),
        _ => format!("<use library=\"{name}\"/>"),
    };
    let edited = edit::add_to_root(text, &snippet, "use").ok()?;
    Some(Fix {
        title: format!("{}: add {snippet}", d.code()),
        text: edited,
        preferred: false,
    })
}

/// `path` as seen from the folder `dir` (`../lib/x.lib.xml`).
fn relative(path: &Path, dir: &Path) -> PathBuf {
    let (a, b): (Vec<_>, Vec<_>) = (path.components().collect(), dir.components().collect());
    let common = a.iter().zip(&b).take_while(|(x, y)| x == y).count();
    let mut out: PathBuf = b[common..].iter().map(|_| "..").collect();
    out.extend(&a[common..]);
    out
}

/// "write the unit: `0.4 m`" (P110), "write `robot-pc` here too" (X103): the text the
/// finding points at, without the blanks around it, becomes the one the help writes.
fn rewrite(d: &Diagnostic, text: &str) -> Option<Fix> {
    let help = d.help.as_deref()?;
    let new = match help.strip_prefix("write the unit: `") {
        Some(rest) => &rest[..rest.find('`')?],
        None => {
            let rest = help.strip_prefix("write `")?;
            let end = rest.find('`')?;
            rest[end..]
                .starts_with("` here too")
                .then(|| &rest[..end])?
        }
    };
    let s = d.primary.span;
    let written = text.get(s.start as usize..s.end as usize)?;
    let inner = written.trim();
    if inner.is_empty() || inner == new {
        return None;
    }
    let start = s.start as usize + (written.len() - written.trim_start().len());
    let mut edited = text.to_owned();
    edited.replace_range(start..start + inner.len(), new);
    Some(Fix {
        title: format!("{}: write `{new}`", d.code()),
        text: edited,
        preferred: false,
    })
}

/// "…, or set <param name="N">V</param> if …" (B103, B108): the parameter set on the
/// module the finding is about, by the `set` operation of `ferroc inspect --edit`.
/// Not where setting it is only half the fix ("set … and connect …", B105).
fn set_param(d: &Diagnostic, result: &CheckResult, text: &str) -> Option<Fix> {
    const SET: &str = "or set <param name=\"";
    let help = d.help.as_deref()?;
    let rest = &help[help.find(SET)? + SET.len()..];
    let (name, rest) = rest.split_once("\">")?;
    let (value, _) = rest.split_once("</param>")?;
    let app = result.app.as_ref()?;
    let here = d.primary.span;
    if here.file != app.span.file {
        return None;
    }
    let (id, _) = app.modules().find(|(id, m)| {
        app.element(*id).name_span == here
            || (m.params.iter()).any(|p| covers(p.span, here) || covers(p.name_span, here))
    })?;
    let module = app.path(id);
    let ops = [Op::Set {
        param: format!("{module}/{name}"),
        value: value.to_string(),
    }];
    let edited = edit::apply(text, &ops).ok()?;
    Some(Fix {
        title: format!(
            "{}: set <param name=\"{name}\">{value}</param> on `{module}`",
            d.code()
        ),
        text: edited.text,
        preferred: false,
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

#[cfg(test)]
mod tests {
    use super::{relative, rewrite};
    use ferroc_compiler::diagnostic::Diagnostic;
    use ferroc_compiler::source::{FileId, Span};

    fn finding(code: &str, text: &str, at: &str, help: &str) -> Diagnostic {
        let start = text.find(at).unwrap();
        let span = Span::new(FileId(0), start, start + at.len());
        let check = ferroc_compiler::checks::find(code).unwrap();
        Diagnostic::new(check, span, "m").help(help)
    }

    #[test]
    fn the_written_value_takes_the_helps_text_and_keeps_its_blanks() {
        let text = "<param name=\"d\"> 0.4 </param> <!-- as measured -->";
        let d = finding(
            "P110",
            text,
            " 0.4 ",
            "write the unit: `0.4 m` (or the unit meant)",
        );
        let fix = rewrite(&d, text).unwrap();
        assert_eq!(fix.text, text.replace(" 0.4 ", " 0.4 m "));
        assert_eq!(fix.title, "P110: write `0.4 m`");
        let text = "<part name=\"b\" host=\"robot-pc\">";
        let d = finding(
            "X103",
            text,
            "robot-pc",
            "write `Robot-PC` here too (host names …)",
        );
        assert_eq!(
            rewrite(&d, text).unwrap().text,
            text.replace("robot-pc", "Robot-PC")
        );
    }

    #[test]
    fn a_manifest_is_named_from_the_files_folder() {
        let p = |s: &str| std::path::PathBuf::from(s);
        assert_eq!(
            relative(&p("/w/m/nav.lib.xml"), &p("/w/m")),
            p("nav.lib.xml")
        );
        assert_eq!(
            relative(&p("/w/lib/g.lib.xml"), &p("/w/m/x")),
            p("../../lib/g.lib.xml")
        );
    }

    #[test]
    fn a_help_that_writes_no_value_for_the_finding_is_not_a_rewrite() {
        // P108's `write `* 1000`` is a step to add, not the text the finding points at.
        let text = "<param name=\"pins\">in/0 -> out[1]</param>";
        let d = finding("P108", text, "in/0 -> out[1]", "write `* 1000`");
        assert!(rewrite(&d, text).is_none());
        let d = finding("X103", "host=\"a\"", "a", "write `a` here too");
        assert!(rewrite(&d, "host=\"a\"").is_none(), "nothing to change");
    }
}
