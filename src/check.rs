//! `ferroc check`: find the models under the given paths, check each, report the
//! findings in the chosen format and exit with what they say.

use crate::{loader_options, output};
use clap::ValueEnum;
use ferroc_compiler::diagnostic::Severity;
use ferroc_compiler::load::Options;
use ferroc_compiler::report::{self, ModelReport};
use ferroc_compiler::{check_model, CheckResult, Policy};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(clap::Args)]
pub struct CheckArgs {
    /// Model files or folders to check
    #[arg(required = true)]
    paths: Vec<PathBuf>,
    /// Output format
    #[arg(long, value_enum, default_value_t = Format::Human)]
    format: Format,
    /// Treat warnings as errors: `--deny warnings`
    #[arg(long, value_name = "warnings")]
    deny: Vec<DenyLevel>,
    /// Silence a code everywhere (repeatable): `--allow T110`
    #[arg(long, value_name = "CODE")]
    allow: Vec<String>,
    /// Extra folders searched for `NAME.lib.xml` manifests (also FERROC_LIB_PATH, `:`-separated)
    #[arg(long, value_name = "DIR")]
    lib_path: Vec<PathBuf>,
    /// Permit <include href> outside the model's folder
    #[arg(long)]
    allow_outside_includes: bool,
    /// Judge deadlocks by this framework's execution semantics, whatever the model's
    /// <application profile> says
    #[arg(
        long,
        value_enum,
        long_help = "Judge deadlocks by this framework's execution semantics, whatever the \
model's <application profile> says. generic: a service runs in the server's thread container \
and a call through an unconnected client waits (D109). finroc: a call to a service in the same \
part runs inline in the caller's thread unless the service declares executes=, and an \
unconnected call fails at once (D111)."
    )]
    profile: Option<ProfileArg>,
    /// Judge the model as run with `ferroc run --lockstep`: also report what makes such a
    /// run differ from the next (X106: modules reading the wall clock or the OS's randomness)
    #[arg(long)]
    lockstep: bool,
    /// FINROC files: the checkout root their group and config files are looked up in
    /// (default: the nearest folder above holding a make.xml, else the file's folder)
    #[arg(long, value_name = "DIR")]
    finroc_root: Option<PathBuf>,
    /// FINROC make.xml: the checkout's target prefix (`rrlib_math`, `finroc_plugins_ib2c`)
    /// when the folder name does not tell it
    #[arg(long, value_name = "PREFIX")]
    finroc_prefix: Option<String>,
}

#[derive(Clone, Copy, ValueEnum, PartialEq)]
enum Format {
    /// rustc-style, with source excerpts
    Human,
    /// FILE:LINE:COL: SEVERITY[CODE]: message
    Short,
    /// documented in docs/json-format.md
    Json,
    /// SARIF 2.1.0 for code scanning
    Sarif,
    /// JUnit XML, one test case per check
    Junit,
}

#[derive(Clone, Copy, ValueEnum)]
enum DenyLevel {
    Warnings,
}

/// Model files under the given paths: files as given, folders searched recursively
/// for application models and FINROC files; every other file found is named in
/// `skipped` with the reason.
fn collect_models(
    paths: &[PathBuf],
    skipped: &mut Vec<(PathBuf, String)>,
) -> Result<Vec<PathBuf>, String> {
    let mut out = Vec::new();
    for p in paths {
        if ferroc_compiler::load::is_stdin(p) {
            out.push(p.clone()); // read once, when it is checked
        } else if p.is_dir() {
            let mut found = Vec::new();
            walk(p, &mut found, skipped, 0);
            found.sort();
            if found.is_empty() {
                return Err(format!(
                    "{} holds no model to check (*.xml with root <application>, or a FINROC make.xml)",
                    p.display()
                ));
            }
            out.extend(found);
        } else if p.exists() {
            out.push(p.clone());
        } else {
            return Err(format!("{}: no such file or folder", p.display()));
        }
    }
    Ok(out)
}

fn walk(dir: &Path, out: &mut Vec<PathBuf>, skipped: &mut Vec<(PathBuf, String)>, depth: usize) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        skipped.push((dir.to_path_buf(), "folder cannot be read".into()));
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        let Ok(kind) = entry.file_type() else {
            skipped.push((path, "its file type cannot be read".into()));
            continue;
        };
        if entry.file_name().to_string_lossy().starts_with('.') {
            // Hidden files and folders (.git, editor backups): named once, not entered.
            skipped.push((path, "hidden (name starts with `.`)".into()));
            continue;
        }
        if kind.is_dir() && depth < 16 {
            walk(&path, out, skipped, depth + 1);
        } else if kind.is_dir() {
            skipped.push((path, "folder nested deeper than 16 levels".into()));
        } else if !kind.is_file() {
            skipped.push((path, "not a regular file".into()));
        } else if let Some(reason) = skip_reason(&path) {
            skipped.push((path, reason));
        } else {
            out.push(path);
        }
    }
}

/// Why a folder scan does not check a file, or `None` for application models and the
/// FINROC files ferroc reads (make.xml, applications, groups, config files, sync configs).
fn skip_reason(path: &Path) -> Option<String> {
    let name = path.to_string_lossy();
    if name.ends_with(".lib.xml") {
        return Some("a library manifest (checked where a model uses it)".into());
    }
    let finroc_ext = path.extension().is_some_and(|e| e == "finroc");
    if !finroc_ext && path.extension().is_none_or(|e| e != "xml") {
        return Some("not an .xml or .finroc file".into());
    }
    if ferroc_compiler::finroc::kind_of(path).is_some() {
        return None;
    }
    Some(match ferroc_compiler::load::root_element(path) {
        Some(r) if r == "application" => return None,
        Some(r) if r == "fragment" => "a model fragment (checked where a model includes it)".into(),
        Some(r) => format!("root element <{r}> is neither a ferroc model nor a FINROC file"),
        None => "no XML root element could be read".into(),
    })
}

/// `--profile`: the execution semantics deadlocks are judged by.
#[derive(Clone, Copy, ValueEnum)]
enum ProfileArg {
    Generic,
    Finroc,
}

pub fn run(args: CheckArgs) -> ExitCode {
    let (options, policy) = match options_and_policy(&args) {
        Ok(o) => o,
        Err(code) => return code,
    };
    let mut skipped = Vec::new();
    let mut tool_errors = Vec::new();
    let models = match collect_models(&args.paths, &mut skipped) {
        Ok(m) => m,
        // The machine formats still write their document, saying that ferroc could
        // not run (a CI reading only that file must not see a clean check).
        Err(e) if matches!(args.format, Format::Json | Format::Sarif | Format::Junit) => {
            tool_errors.push(e);
            Vec::new()
        }
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    let progress =
        models.len() > 1 && args.format == Format::Human && std::io::stderr().is_terminal();
    let results = check_all(&models, &options, &policy, progress, &mut tool_errors);
    let reports: Vec<(String, ModelReport<'_>)> = results
        .iter()
        .map(|(p, r)| {
            (
                p.clone(),
                ModelReport {
                    sources: &r.sources,
                    diagnostics: &r.diagnostics,
                },
            )
        })
        .collect();
    let out = match args.format {
        Format::Human => human(&reports, &results, &skipped),
        format => {
            let out = machine(format, &reports, &tool_errors);
            // Machine formats keep stdout to themselves; what was skipped goes to stderr.
            for line in skipped_lines(&skipped, &results) {
                eprintln!("{line}");
            }
            out
        }
    };
    if let Err(failed) = output::stdout(out.as_bytes()) {
        return failed; // the report is lost: never exit 0 or 1 as if it was read
    }
    for e in &tool_errors {
        eprintln!("error: {e}");
    }
    let code = if !tool_errors.is_empty() {
        2
    } else if reports
        .iter()
        .any(|(_, r)| r.diagnostics.iter().any(|d| d.severity == Severity::Error))
    {
        1
    } else {
        0
    };
    // The syntax trees and IRs of a large model take a tenth of the run to free, and the
    // operating system reclaims them at once: exit without running their destructors.
    // Everything the user sees has been written and flushed above.
    std::process::exit(code)
}

/// The loader options and the check policy the arguments ask for, or exit code 2 for
/// an `--allow` of a code no check has.
fn options_and_policy(args: &CheckArgs) -> Result<(Options, Policy), ExitCode> {
    let mut options = loader_options(&args.lib_path, args.allow_outside_includes);
    options.profile = args.profile.map(|p| match p {
        ProfileArg::Generic => ferroc_compiler::ir::Profile::Generic,
        ProfileArg::Finroc => ferroc_compiler::ir::Profile::Finroc,
    });
    options.lockstep = args.lockstep;
    for code in &args.allow {
        if ferroc_compiler::checks::find(code).is_none() {
            eprintln!("error: --allow {code}: no check has this code\nhelp: `ferroc explain --list` shows every code");
            return Err(ExitCode::from(2));
        }
    }
    let policy = Policy {
        allow: args.allow.clone(),
        deny_warnings: !args.deny.is_empty(),
    };
    options.finroc_root = args.finroc_root.clone();
    options.finroc_prefix = args.finroc_prefix.clone();
    Ok((options, policy))
}

/// Checks every model in turn (`progress`: counting on standard error); a model that
/// cannot be checked at all becomes a tool error.
fn check_all(
    models: &[PathBuf],
    options: &Options,
    policy: &Policy,
    progress: bool,
    tool_errors: &mut Vec<String>,
) -> Vec<(String, CheckResult)> {
    let mut results = Vec::new();
    let mut seen = std::collections::HashSet::new();
    for (i, path) in models.iter().enumerate() {
        if progress {
            eprint!("\r[{}/{}] {}\x1b[K", i + 1, models.len(), path.display());
        }
        match check_model(path, options, policy) {
            Ok(mut r) => {
                once(&mut r, &mut seen);
                results.push((path.display().to_string(), r));
            }
            Err(e) => tool_errors.push(e),
        }
    }
    if progress {
        eprint!("\r\x1b[K");
    }
    results
}

/// A finding is reported once per check run: two files of a folder can both reach the
/// same place (two FINROC applications linking one config value, a fragment two models
/// include), and the same code at the same place with the same message is one finding.
fn once(
    result: &mut CheckResult,
    seen: &mut std::collections::HashSet<(String, PathBuf, usize, usize, String)>,
) {
    let sources = &result.sources;
    result.diagnostics.retain(|d| {
        let span = d.primary.span;
        seen.insert((
            d.code().to_string(),
            sources.get(span.file).path.clone(),
            span.start as usize,
            span.end as usize,
            d.message.clone(),
        ))
    });
}

/// The human report: every model's findings, what was skipped or not checked, and
/// the counts.
fn human(
    reports: &[(String, ModelReport<'_>)],
    results: &[(String, CheckResult)],
    skipped: &[(PathBuf, String)],
) -> String {
    let mut out = String::new();
    let color = crate::color::enabled(crate::color::Stream::Stdout);
    for (_, r) in reports {
        report::human::render(r, color, &mut out);
    }
    let count = |s| {
        reports
            .iter()
            .map(|(_, r)| r.diagnostics.iter().filter(|d| d.severity == s).count())
            .sum::<usize>()
    };
    for line in skipped_lines(skipped, results) {
        out.push_str(&line);
        out.push('\n');
    }
    out.push_str(&format!(
        "checked {} file(s), skipped {}: {} error(s), {} warning(s), {} note(s)\n",
        reports.len(),
        skipped.len(),
        count(Severity::Error),
        count(Severity::Warning),
        count(Severity::Note)
    ));
    out
}

/// `skipped PATH: WHY` for every file a folder scan passed over, then `not checked:`
/// for what the checked models left out.
fn skipped_lines(skipped: &[(PathBuf, String)], results: &[(String, CheckResult)]) -> Vec<String> {
    let skipped = (skipped.iter()).map(|(path, why)| format!("skipped {}: {why}", path.display()));
    let not_checked = (results.iter())
        .flat_map(|(_, r)| &r.not_checked)
        .map(|line| format!("not checked: {line}"));
    skipped.chain(not_checked).collect()
}

/// The report in a machine format (every format but `human`), tool errors included
/// where the format has a place for them.
fn machine(
    format: Format,
    reports: &[(String, ModelReport<'_>)],
    tool_errors: &[String],
) -> String {
    let mut out = String::new();
    match format {
        Format::Human => {}
        Format::Short => reports.iter().for_each(|(_, r)| report::short(r, &mut out)),
        Format::Json => {
            let models = reports
                .iter()
                .map(|(p, r)| report::json::model(p, r))
                .collect();
            let errors = tool_errors
                .iter()
                .map(|e| serde_json::Value::String(e.clone()))
                .collect();
            out = serde_json_pretty(&report::json::document(models, errors));
        }
        Format::Sarif => {
            let rs: Vec<ModelReport<'_>> = reports
                .iter()
                .map(|(_, r)| ModelReport {
                    sources: r.sources,
                    diagnostics: r.diagnostics,
                })
                .collect();
            let mut doc = report::sarif::document(&rs);
            report::sarif::add_invocation(&mut doc, tool_errors);
            out = serde_json_pretty(&doc);
        }
        Format::Junit => out = report::junit::document(reports, tool_errors),
    }
    out
}

fn serde_json_pretty(v: &serde_json::Value) -> String {
    let mut s = serde_json::to_string_pretty(v).unwrap_or_default();
    s.push('\n');
    s
}
