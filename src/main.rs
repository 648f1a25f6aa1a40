//! `ferroc`: the command line. Subcommands parse arguments and call the compiler.

use clap::{Parser, Subcommand, ValueEnum};
use ferroc_compiler::checks::REGISTRY;
use ferroc_compiler::diagnostic::Severity;
use ferroc_compiler::load::{BuiltinLibrary, Options};
use ferroc_compiler::report::{self, ModelReport};
use ferroc_compiler::{check_model, CheckResult, Policy};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

mod bundle;
mod checked;
mod graph;
mod interface;
mod output;
mod run;
mod schedule;
mod types;

/// mimalloc: checking a large model makes millions of small allocations, and glibc's
/// allocator spent a sixth of the run in malloc/free (measured on B1).
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// The standard library's manifest, built into the tool.
const FERROC_STD: &str = include_str!("../components/ferroc_std.lib.xml");

#[derive(Parser)]
#[command(
    name = "ferroc",
    version,
    about = "Model compiler for robot control software",
    long_about = "ferroc checks XML application models of robot control software the way a compiler \
checks a program: structure, types and units, parameters, libraries, deployment.\n\n\
Examples:\n  ferroc check models/crash_course.xml\n  ferroc check models/ --format sarif > ferroc.sarif\n  ferroc explain T102"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Check models and report findings (exit 0 clean, 1 findings that fail, 2 could not run)
    #[command(
        long_about = "Check one or more application models. Folders are searched for `*.xml` files \
whose root is <application> (manifests `*.lib.xml` and fragments are skipped).\n\n\
Exit codes: 0 no errors (warnings allowed), 1 errors (or warnings with --deny warnings), 2 ferroc could not run."
    )]
    Check(CheckArgs),
    /// Show the static execution order of every thread container
    #[command(
        long_about = "Check a model, then print for each thread container the order in which its \
steps run every cycle (sense steps, then control steps, topological along data edges, ties by \
path) and the edges where loops were broken. This is the order `ferroc run` executes.\n\n\
Example:\n  ferroc schedule models/crash_course.xml"
    )]
    Schedule(schedule::ScheduleArgs),
    /// Check a model, then run it in the ferroc runtime until Ctrl-C, --for or --cycles
    #[command(
        long_about = "Check a model (errors stop here), build it in the runtime from the module \
types built into this binary, and run every thread container in this process. A live status \
line (cycles, overruns, load per thread container) is shown on a terminal. Ctrl-C or SIGTERM \
stops cleanly after the current cycle. A module that panics is reported with its path and \
stopped; the others keep running, and the exit code is 1.\n\n\
A module type whose Rust interface differs from its manifest is refused.\n\n\
Connections, calls and parameter links between parts travel as links (encoded, paced by \
`sharing=`), as between the programs of a bundle. --lockstep runs in simulated time and prints \
the same on every run (docs/links-and-lockstep.md).\n\n\
Examples:\n  ferroc run models/crash_course.xml\n  ferroc run models/crash_course.xml --for 10s\n  \
ferroc run models/crash_course.xml --cycles 100 --param front-noise=5cm\n  \
ferroc run models/rescue_robot.xml --lockstep --cycles 100"
    )]
    Run(run::RunArgs),
    /// Check a model, then write a Cargo workspace with one program per part (wiring only)
    #[command(
        long_about = "Check a model (errors stop here), plan it as `ferroc run` does, and write DIR: a \
Cargo workspace with one program per part whose generated `main.rs` makes the same runtime \
Builder calls `ferroc run` makes, with the concrete module types (wiring only: no module logic \
is generated). Next to it: the resolved model (`model/APP.xml`, which `ferroc check` accepts), \
`manifest.json` (tool version, model hash, parts, hosts, binaries, commands), a launch script per \
host (`launch/HOST.sh`) and a systemd unit per part (`systemd/`).\n\n\
The output is deterministic: the same model gives a byte-identical bundle. DIR must be empty or \
new (or pass --force); it is never a symbolic link, and nothing is written outside it.\n\n\
Exit codes: 0 written, 1 the model has errors or cannot be bundled, 2 bad arguments or DIR \
unusable.\n\n\
Examples:\n  ferroc bundle models/crash_course.xml -o dist/crash_course\n  \
cargo build --release --manifest-path dist/crash_course/Cargo.toml\n  \
dist/crash_course/target/release/crash_course-fragile_bot --cycles 100\n  \
ferroc bundle models/crash_course.xml -o dist/cc --deps version --prefix /opt/robot"
    )]
    Bundle(bundle::BundleArgs),
    /// Draw the application as a graph (behaviour networks the iB2C way): DOT or SVG
    #[command(
        long_about = "Draw the application as a Graphviz graph: modules grouped by part and group, \
behaviours as boxes with their meta inputs on top (s stimulation, i0.. inhibition, ch k fusion \
channels) and meta outputs below (a activity, derived activities, r target rating). \
Stimulation edges are green arrows, inhibition edges red bars, activities and target ratings \
into a fusion blue dashed, data grey. Edges run module to module through group ports.\n\n\
`--format svg` needs Graphviz `dot` on PATH.\n\n\
Examples:\n  ferroc graph models/warehouse_fleet.xml > fleet.dot\n  \
ferroc graph models/warehouse_fleet.xml --format svg -o fleet.svg"
    )]
    Graph(graph::GraphArgs),
    /// The module types built into this binary: list them, export or check their manifests
    Types(types::TypesArgs),
    /// Explain a finding code: what it protects, a bad example, the fix
    Explain {
        /// A code (`T102`) or a check name (`incompatible-types`)
        code: Option<String>,
        /// List every code with its severity and summary
        #[arg(long)]
        list: bool,
    },
}

#[derive(clap::Args)]
struct CheckArgs {
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
    /// Colour in human output: auto, always, never
    #[arg(long, value_enum, default_value_t = ColorChoice::Auto)]
    color: ColorChoice,
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

#[derive(Clone, Copy, ValueEnum)]
enum ColorChoice {
    Auto,
    Always,
    Never,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Check(args) => check(args),
        Command::Schedule(args) => schedule::run(args),
        Command::Run(args) => run::run(args),
        Command::Bundle(args) => bundle::run(args),
        Command::Graph(args) => graph::run(args),
        Command::Types(args) => types::run(args),
        Command::Explain { code, list } => explain(code, list),
    }
}

fn explain(code: Option<String>, list: bool) -> ExitCode {
    if list || code.is_none() {
        let mut out = String::new();
        for c in REGISTRY {
            out.push_str(&format!(
                "{}  {:<8} {:<34} {}\n",
                c.code,
                c.severity.as_str(),
                c.name,
                c.summary
            ));
        }
        return output::stdout_then(out.as_bytes(), ExitCode::SUCCESS);
    }
    let code = code.unwrap_or_default();
    match ferroc_compiler::checks::find(&code) {
        Some(c) => {
            let text = format!(
                "{} {} ({})\n\n{}\n\n{}\n",
                c.code,
                c.name,
                c.severity.as_str(),
                c.summary,
                c.explanation
            );
            output::stdout_then(text.as_bytes(), ExitCode::SUCCESS)
        }
        None => {
            eprintln!("error: no check has the code `{code}`\nhelp: `ferroc explain --list` shows every code");
            ExitCode::from(2)
        }
    }
}

/// Model files under the given paths: files as given, folders searched recursively
/// for `*.xml` files whose root element is <application>.
fn collect_models(paths: &[PathBuf]) -> Result<Vec<PathBuf>, String> {
    let mut out = Vec::new();
    for p in paths {
        if ferroc_compiler::load::is_stdin(p) {
            out.push(p.clone()); // read once, when it is checked
        } else if p.is_dir() {
            let mut found = Vec::new();
            walk(p, &mut found, 0);
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

fn walk(dir: &Path, out: &mut Vec<PathBuf>, depth: usize) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        let Ok(kind) = entry.file_type() else {
            continue;
        };
        if entry.file_name().to_string_lossy().starts_with('.') {
            continue; // hidden files and folders (.git, editor backups)
        }
        if kind.is_dir() && depth < 16 {
            walk(&path, out, depth + 1);
        } else if kind.is_file()
            && path.extension().is_some_and(|e| e == "xml")
            && !path.to_string_lossy().ends_with(".lib.xml")
            && is_checkable(&path)
        {
            out.push(path);
        }
    }
}

/// Files a folder scan picks up: application models and FINROC `make.xml` files.
fn is_checkable(path: &Path) -> bool {
    matches!(
        ferroc_compiler::load::root_element(path).as_deref(),
        Some("application" | "targets")
    )
}

/// Loader options shared by every command that reads models.
pub(crate) fn loader_options(lib_path: &[PathBuf], allow_outside_includes: bool) -> Options {
    let mut lib_path = lib_path.to_vec();
    if let Ok(env) = std::env::var("FERROC_LIB_PATH") {
        lib_path.extend(std::env::split_paths(&env));
    }
    Options {
        lib_path,
        builtins: vec![BuiltinLibrary {
            name: "ferroc_std".into(),
            text: FERROC_STD.into(),
        }],
        allow_outside_includes,
        ..Options::default()
    }
}

/// `--profile`: the execution semantics deadlocks are judged by.
#[derive(Clone, Copy, ValueEnum)]
enum ProfileArg {
    Generic,
    Finroc,
}

fn check(args: CheckArgs) -> ExitCode {
    let mut options = loader_options(&args.lib_path, args.allow_outside_includes);
    options.profile = args.profile.map(|p| match p {
        ProfileArg::Generic => ferroc_compiler::ir::Profile::Generic,
        ProfileArg::Finroc => ferroc_compiler::ir::Profile::Finroc,
    });
    for code in &args.allow {
        if ferroc_compiler::checks::find(code).is_none() {
            eprintln!("error: --allow {code}: no check has this code\nhelp: `ferroc explain --list` shows every code");
            return ExitCode::from(2);
        }
    }
    let policy = Policy {
        allow: args.allow.clone(),
        deny_warnings: !args.deny.is_empty(),
    };
    let mut tool_errors = Vec::new();
    let models = match collect_models(&args.paths) {
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
    let mut results: Vec<(String, CheckResult)> = Vec::new();
    for (i, path) in models.iter().enumerate() {
        if progress {
            eprint!("\r[{}/{}] {}\x1b[K", i + 1, models.len(), path.display());
        }
        match check_model(path, &options, &policy) {
            Ok(r) => results.push((path.display().to_string(), r)),
            Err(e) => tool_errors.push(e),
        }
    }
    if progress {
        eprint!("\r\x1b[K");
    }
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
    let mut out = String::new();
    match args.format {
        Format::Human => {
            let color = match args.color {
                ColorChoice::Always => true,
                ColorChoice::Never => false,
                ColorChoice::Auto => {
                    std::io::stdout().is_terminal() && std::env::var_os("NO_COLOR").is_none()
                }
            };
            for (_, r) in &reports {
                report::human::render(r, color, &mut out);
            }
            let count = |s| {
                reports
                    .iter()
                    .map(|(_, r)| r.diagnostics.iter().filter(|d| d.severity == s).count())
                    .sum::<usize>()
            };
            out.push_str(&format!(
                "checked {} model(s): {} error(s), {} warning(s), {} note(s)\n",
                reports.len(),
                count(Severity::Error),
                count(Severity::Warning),
                count(Severity::Note)
            ));
        }
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
            report::sarif::add_invocation(&mut doc, &tool_errors);
            out = serde_json_pretty(&doc);
        }
        Format::Junit => out = report::junit::document(&reports, &tool_errors),
    }
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

fn serde_json_pretty(v: &serde_json::Value) -> String {
    let mut s = serde_json::to_string_pretty(v).unwrap_or_default();
    s.push('\n');
    s
}
