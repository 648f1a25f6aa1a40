//! ferroc's compiler: parse → resolve → IR → checks → reports.
//!
//! The entry point is [`check_model`]: one model file in, its findings (and the IR, when
//! it could be built) out. The pipeline's stages are crates of their own
//! (`ferroc-diagnostics`, `-values`, `-syntax`, `-model`, `-schedule`, `-deadlock`,
//! `-checks`, `-finroc`, `-report`, `-plan`); this crate runs them in order, keeps the
//! registry of every check, and re-exports their modules under the paths they had when
//! they were one crate (`ferroc_compiler::ir`, `::load`, …). See `ARCHITECTURE.md`.

#![forbid(unsafe_code)]

pub mod checks;
pub mod graph;
pub mod report;

pub use ferroc_deadlock as deadlock;
pub use ferroc_diagnostics::{diagnostic, source};
pub use ferroc_finroc as finroc;
pub use ferroc_model::{ir, library, load, load_manifests, resolve, LoadedLibraries};
pub use ferroc_plan::{edit, plan};
pub use ferroc_schedule as schedule;
pub use ferroc_syntax as syntax;
pub use ferroc_values::{types, units, values};

use diagnostic::{Diagnostic, Diagnostics, Severity};
use load::{Loader, Options};
use source::SourceMap;
use std::path::Path;

/// The outcome of checking one model.
pub struct CheckResult {
    pub sources: SourceMap,
    pub diagnostics: Vec<Diagnostic>,
    pub app: Option<ir::Application>,
    pub libraries: library::LibrarySet,
    /// What was not checked and why (FINROC files: types not in the catalogue, links
    /// without a config file), one sentence each.
    pub not_checked: Vec<String>,
}

/// How users promote or silence findings.
#[derive(Clone, Debug, Default)]
pub struct Policy {
    /// Codes silenced everywhere (`--allow`).
    pub allow: Vec<String>,
    /// Warnings become errors (`--deny warnings`).
    pub deny_warnings: bool,
}

/// Checks one model. `Err` only when the model file itself cannot be read (exit code 2).
pub fn check_model(path: &Path, options: &Options, policy: &Policy) -> Result<CheckResult, String> {
    check_with(path, None, options, policy)
}

/// Checks `text` as the model at `path` (an edited model, `ferroc run --inspect`): every
/// check runs as for the file, includes and manifests are found from the file's folder,
/// and diagnostics name the text `name` (`models/x.xml (edited)`).
pub fn check_model_text(
    path: &Path,
    name: &str,
    text: &str,
    options: &Options,
    policy: &Policy,
) -> Result<CheckResult, String> {
    check_with(path, Some((name, text)), options, policy)
}

fn check_with(
    path: &Path,
    given: Option<(&str, &str)>,
    options: &Options,
    policy: &Policy,
) -> Result<CheckResult, String> {
    let mut sources = SourceMap::default();
    let mut diags = Diagnostics::default();
    let mut loader = Loader::new(&mut sources, &mut diags, options);
    if let Some((name, text)) = given {
        loader.set_model_text(name.to_owned(), text.to_owned());
    }
    // A FINROC file (make.xml, application, group, config) is checked as such: there is
    // no model. Standard input is read once here to see its root element (a pipe cannot
    // be read twice).
    let kind = if given.is_some() {
        None
    } else if load::is_stdin(path) {
        let text = load::read_stdin(&options.limits)
            .map_err(|r| format!("cannot read {}: {r}", path.display()))?;
        let root = load::root_element_of(text.as_bytes());
        loader.set_stdin_text(text);
        finroc::kind_of_root(root.as_deref(), path)
    } else {
        finroc::kind_of(path)
    };
    let mut not_checked = Vec::new();
    let model = match kind {
        Some(kind) => {
            not_checked = finroc::check_file(&mut loader, path, kind)?;
            None
        }
        None => loader.load_model(path)?,
    };
    let mut app = None;
    let mut libraries = library::LibrarySet::default();
    if let Some(model) = model {
        let requests = model
            .root
            .children_named("use")
            .filter_map(|u| {
                Some(library::LibraryRequest {
                    name: u.value("library")?.to_string(),
                    manifest: u.value("manifest").map(str::to_string),
                    span: u.value_span("library"),
                    from_file: model.file,
                })
            })
            .collect();
        let (set, used) = library::load_libraries(&mut loader, requests);
        libraries = set;
        let used: Vec<_> = used.into_iter().flatten().collect();
        let resolved = resolve::resolve(&mut loader, &model, &libraries, &used);
        // Nothing after resolving reads the syntax trees (the passes read the IR), and
        // they are the largest structure of a big model: free them here, on this
        // thread, before the passes allocate their tables, so those tables reuse the
        // trees' memory. Freed on a thread of their own (as before), the trees were
        // still resident while the passes took fresh pages, and the peak was the sum
        // of both (B1: +23 MiB at 100,000 modules in an RSS trace; the frees cost the
        // same CPU on either thread).
        drop(model);
        let allows = std::mem::take(&mut loader.allows);
        let ctx = ferroc_checks::PassContext::new(&resolved, &libraries, loader.sources);
        ferroc_checks::run_passes(&ctx, loader.diags);
        loader.allows = allows;
        app = Some(resolved);
    }
    let allows = std::mem::take(&mut loader.allows);
    let mut items = std::mem::take(&mut diags.items);
    for allow in &allows {
        if checks::find(&allow.code).is_none() {
            items.push(
                Diagnostic::new(
                    &checks::m118_unknown_code_in_allow::CHECK,
                    allow.span,
                    format!("no check has the code `{}`", allow.code),
                )
                .label("unknown code")
                .help("see `ferroc explain --list` for the codes"),
            );
        }
    }
    items.retain(|d| {
        !policy
            .allow
            .iter()
            .any(|a| a.eq_ignore_ascii_case(d.code()) || a == d.check.name)
            && !allows.iter().any(|a| {
                a.code.eq_ignore_ascii_case(d.code()) && a.region.contains(&d.primary.span)
            })
    });
    if policy.deny_warnings {
        for d in &mut items {
            if d.severity == Severity::Warning {
                d.severity = Severity::Error;
            }
        }
    }
    // Stable order: by file, position, code. One finding per code and place: a group type
    // used many times reports a problem in its definition once.
    items.sort_by(|a, b| {
        (
            a.primary.span.file,
            a.primary.span.start,
            a.code(),
            &a.message,
        )
            .cmp(&(
                b.primary.span.file,
                b.primary.span.start,
                b.code(),
                &b.message,
            ))
    });
    items.dedup_by(|a, b| a.code() == b.code() && a.primary.span == b.primary.span);
    Ok(CheckResult {
        sources,
        diagnostics: items,
        app,
        libraries,
        not_checked,
    })
}
