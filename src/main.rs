//! `ferroc`: the command line. Subcommands parse arguments and call the compiler.

use clap::{Parser, Subcommand, ValueEnum};
use ferroc_compiler::checks::REGISTRY;
use ferroc_compiler::diagnostic::Severity;
use ferroc_compiler::load::Options;
use ferroc_compiler::report::{self, ModelReport};
use ferroc_compiler::{check_model, CheckResult, Policy};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// `eprintln!` that does not panic when standard error is closed or full (see
/// `ferroc_runtime::console::stderr_line`); it shadows std's in this whole crate.
macro_rules! eprintln {
    ($($arg:tt)*) => {
        ferroc_runtime::console::stderr_line(format_args!($($arg)*))
    };
}

mod bundle;
mod finroc;
mod graph;
mod inspect;
mod inspect_edit;
mod log;
mod new;
mod runner;
mod schedule;

// `run` and `types` live in ferroc_host, shared with the runners ferroc generates.
pub(crate) use ferroc_host::{checked, output, run, types};

/// mimalloc: checking a large model makes millions of small allocations, and glibc's
/// allocator spent a sixth of the run in malloc/free (measured on B1).
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

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
        long_about = "Check application models and FINROC files (make.xml, .finroc applications, \
group files, config files, finroc_sync configs; docs/finroc.md). Folders are searched for \
`*.xml` and `*.finroc` files; every other file found is named with the reason it was skipped \
(manifests `*.lib.xml` and fragments are checked where they are used), and what could not be \
checked is listed (human format on stdout, other formats on stderr).\n\n\
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
        long_about = "Check a model (errors stop here), build it in the runtime with the module \
types of its libraries, and run every thread container in one process. The standard library \
is built into ferroc; for other libraries ferroc builds a runner program linking their crates \
(the manifests' `rust-crate`, next to the manifest), once per set of libraries, with cargo in \
their target folder; a changed model needs no rebuild. A live status \
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
    /// The module types of libraries' crates: list them, export or check their manifests
    Types(types::TypesArgs),
    /// Start a library crate (module, manifest, test, model) or a model
    New(new::NewArgs),
    /// Import an application from another framework as a ferroc model
    #[command(subcommand)]
    Import(finroc::ImportFormat),
    /// Export a file in another framework's format
    #[command(subcommand)]
    Export(finroc::ExportFormat),
    /// Show what an MCAP recording holds (ferroc_std.Logger's, ferroc run --record's)
    #[command(
        long_about = "Show what an MCAP recording holds: `info` lists its channels (topic, \
encoding, ferroc type, part, message count) and log-time span; `cat` prints one topic's \
messages, one line each (log time in seconds, then the JSON form, or with --exact the exact \
postcard bytes in hex). A recording cut off by a crash is read up to the cut, and says so.\n\n\
Examples:\n  ferroc run models/crash_course.xml --lockstep --for 5s --record run.mcap\n  \
ferroc log info run.mcap\n  ferroc log cat run.mcap --channel bot/simulation/distance_front"
    )]
    Log(log::LogArgs),
    /// Look into a program running with --inspect: list, get, set, watch
    #[command(
        long_about = "Look into a running program over Zenoh (docs/inspect.md): `ferroc run MODEL \
--inspect` serves its element tree, every port's latest value, parameters, thread container \
figures, link state and iB2C activities on 127.0.0.1:47900 and prints a token for changes. \
`ferroc inspect` connects to that address (a Zenoh peer with multicast scouting off) and asks. \
A parameter change is checked (type, unit, range, choices) before it is applied, and needs the \
token.\n\n\
Exit codes: 0 answered, 1 the program refused or does not know the path, 2 no program reached.\n\n\
Examples:\n  ferroc run models/nav_behaviours.xml --inspect &\n  ferroc inspect --list\n  \
ferroc inspect --get robot/avoid/activity\n  \
ferroc inspect --set robot/go_to_goal/max_speed=0.3m/s --token TOKEN\n  \
ferroc inspect --watch robot/avoid/activity --for 5s"
    )]
    Inspect(inspect::InspectArgs),
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
        Command::Run(args) => runner::run(args),
        Command::Bundle(args) => bundle::run(args),
        Command::Graph(args) => graph::run(args),
        Command::Types(args) => runner::types(args),
        Command::New(args) => new::run(args),
        Command::Import(format) => finroc::import(format),
        Command::Export(format) => finroc::export(format),
        Command::Log(args) => log::run(args),
        Command::Inspect(args) => inspect::run(args),
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

/// Loader options shared by every command that reads models.
pub(crate) fn loader_options(lib_path: &[PathBuf], allow_outside_includes: bool) -> Options {
    ferroc_host::loader_options(lib_path, allow_outside_includes)
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
    options.finroc_root = args.finroc_root.clone();
    options.finroc_prefix = args.finroc_prefix.clone();
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
            for (path, why) in &skipped {
                out.push_str(&format!("skipped {}: {why}\n", path.display()));
            }
            for (_, r) in &results {
                for line in &r.not_checked {
                    out.push_str(&format!("not checked: {line}\n"));
                }
            }
            out.push_str(&format!(
                "checked {} file(s), skipped {}: {} error(s), {} warning(s), {} note(s)\n",
                reports.len(),
                skipped.len(),
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
    if args.format != Format::Human {
        // Machine formats keep stdout to themselves; what was skipped goes to stderr.
        for (path, why) in &skipped {
            eprintln!("skipped {}: {why}", path.display());
        }
        for (_, r) in &results {
            for line in &r.not_checked {
                eprintln!("not checked: {line}");
            }
        }
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
