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
use ferroc_syntax::AllowRegion;
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
    let mut not_checked = Vec::new();
    let model = match finroc_kind(&mut loader, path, given.is_some(), options)? {
        Some(kind) => {
            not_checked = finroc::check_file(&mut loader, path, kind)?;
            None
        }
        None => loader.load_model(path)?,
    };
    let mut app = None;
    let mut libraries = library::LibrarySet::default();
    if let Some(model) = model {
        let (resolved, set) = check_loaded_model(&mut loader, model);
        app = Some(resolved);
        libraries = set;
    }
    let allows = std::mem::take(&mut loader.allows);
    let mut items = std::mem::take(&mut diags.items);
    report_unknown_allow_codes(&allows, &mut items);
    apply_policy(&mut items, &allows, policy);
    sort_and_dedup(&mut items);
    Ok(CheckResult {
        sources,
        diagnostics: items,
        app,
        libraries,
        not_checked,
    })
}

/// The FINROC kind of the file at `path` (make.xml, application, group, config), which
/// is checked as such with no model; `None` for a model (always for a given text).
/// Standard input is read once here to see its root element (a pipe cannot be read
/// twice) and handed to the loader.
fn finroc_kind(
    loader: &mut Loader<'_>,
    path: &Path,
    given: bool,
    options: &Options,
) -> Result<Option<finroc::Kind>, String> {
    Ok(if given {
        None
    } else if load::is_stdin(path) {
        let text = load::read_stdin(&options.limits)
            .map_err(|r| format!("cannot read {}: {r}", path.display()))?;
        let root = load::root_element_of(text.as_bytes());
        loader.set_stdin_text(text);
        finroc::kind_of_root(root.as_deref(), path)
    } else {
        finroc::kind_of(path)
    })
}

/// Loads the libraries a model uses, resolves it into the IR and runs every pass on it.
fn check_loaded_model(
    loader: &mut Loader<'_>,
    model: load::ModelFiles,
) -> (ir::Application, library::LibrarySet) {
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
    let (libraries, used) = library::load_libraries(loader, requests);
    let used: Vec<_> = used.into_iter().flatten().collect();
    let resolved = resolve::resolve(loader, &model, &libraries, &used);
    // Nothing after resolving reads the syntax trees (the passes read the IR), and
    // they are the largest structure of a big model: free them here, on this
    // thread, before the passes allocate their tables, so those tables reuse the
    // trees' memory. Freed on a thread of their own (as before), the trees were
    // still resident while the passes took fresh pages, and the peak was the sum
    // of both (B1: +23 MiB at 100,000 modules in an RSS trace; the frees cost the
    // same CPU on either thread).
    drop(model);
    let allows = std::mem::take(&mut loader.allows);
    let mut ctx = ferroc_checks::PassContext::new(&resolved, &libraries, loader.sources);
    ctx.lockstep = loader.options.lockstep;
    ferroc_checks::run_passes(&ctx, loader.diags);
    loader.allows = allows;
    (resolved, libraries)
}

/// M118 for every `allow` that names no check.
fn report_unknown_allow_codes(allows: &[AllowRegion], items: &mut Vec<Diagnostic>) {
    for allow in allows {
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
}

/// Drops the findings `--allow` or an `allow` region silences; `--deny warnings` makes
/// the remaining warnings errors.
fn apply_policy(items: &mut Vec<Diagnostic>, allows: &[AllowRegion], policy: &Policy) {
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
        for d in items {
            if d.severity == Severity::Warning {
                d.severity = Severity::Error;
            }
        }
    }
}

/// Stable order: by file, position, code. One finding per code and place: a group type
/// used many times reports a problem in its definition once.
fn sort_and_dedup(items: &mut Vec<Diagnostic>) {
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
}
