//! `ferroc`: the command line. Subcommands parse arguments and call the compiler.

#![forbid(unsafe_code)]

use clap::{Parser, Subcommand};
use ferroc_compiler::checks::REGISTRY;
use ferroc_compiler::load::Options;
use std::path::PathBuf;
use std::process::ExitCode;

/// `eprintln!` that does not panic when standard error is closed or full (see
/// `ferroc_runtime::console::stderr_line`); it shadows std's in this whole crate.
macro_rules! eprintln {
    ($($arg:tt)*) => {
        ferroc_runtime::console::stderr_line(format_args!($($arg)*))
    };
}

mod bundle;
mod check;
mod color;
mod completions;
mod finroc;
mod graph;
mod inspect;
mod inspect_edit;
mod log;
mod man;
mod new;
mod runner;
mod schedule;

// `run` and `types` live in ferroc_host, shared with the runners ferroc generates.
pub(crate) use ferroc_host::{check_first, from_plan, output, run, types};

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
    /// Colour: auto (on a terminal, unless NO_COLOR is set), always, never
    #[arg(long, global = true, value_enum, default_value_t, value_name = "WHEN")]
    color: color::ColorChoice,
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
Exit codes: 0 no errors (warnings allowed), 1 errors (or warnings with --deny warnings), 2 ferroc could not run.\n\n\
Examples:\n  ferroc check models/crash_course.xml\n  \
ferroc check models/crash_course.xml --format json"
    )]
    Check(check::CheckArgs),
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
ferroc log info run.mcap\n  ferroc log cat run.mcap --channel fragile_bot/main/control/controller/velocity"
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
ferroc inspect --get robot/control/avoid/activity\n  \
ferroc inspect --set robot/control/go_to_goal/max_speed=0.3m/s --token TOKEN\n  \
ferroc inspect --watch robot/control/avoid/activity --for 5s"
    )]
    Inspect(inspect::InspectArgs),
    /// Language server for editors: live findings, go to definition, hover, completion, quick fixes
    #[command(
        long_about = "Serve the Language Server Protocol over standard input and output, for an \
editor to start (docs/editors.md). Every check `ferroc check` runs is reported as you type, \
for models, included fragments, library manifests and FINROC files; go to definition, hover, \
completion, document symbols and quick fixes from `did you mean` hints."
    )]
    Lsp {
        /// Extra folders searched for `NAME.lib.xml` manifests (also FERROC_LIB_PATH)
        #[arg(long, value_name = "DIR")]
        lib_path: Vec<PathBuf>,
        /// Accepted for clients that pass it; standard input and output are the only transport
        #[arg(long)]
        stdio: bool,
    },
    /// Explain a finding code: what it protects, a bad example, the fix
    Explain {
        /// A code (`T102`) or a check name (`incompatible-types`)
        code: Option<String>,
        /// List every code with its severity and summary
        #[arg(long)]
        list: bool,
    },
    /// Print a shell completion script (bash, zsh, fish, elvish, powershell)
    #[command(long_about = completions::LONG_ABOUT)]
    Completions(completions::CompletionsArgs),
    /// Print the manual page of ferroc or of one command (roff), or write them all
    #[command(long_about = man::LONG_ABOUT)]
    Man(man::ManArgs),
}

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return parse_error(&e),
    };
    color::choose(cli.color);
    match cli.command {
        Command::Check(args) => check::run(args),
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
        Command::Lsp { lib_path, .. } => lsp(&lib_path),
        Command::Completions(args) => completions::run(&args),
        Command::Man(args) => man::run(&args),
    }
}

/// `--help`, `--version` and bad arguments: help and version go to standard output
/// like any report (a full disk is exit code 2, not a silent 0), usage errors to
/// standard error with clap's exit code (2).
fn parse_error(e: &clap::Error) -> ExitCode {
    use color::{ColorChoice, Stream};
    let chosen = ColorChoice::from_args(std::env::args_os().skip(1));
    if e.use_stderr() {
        let text = e.render();
        let text = if chosen.colours(Stream::Stderr) {
            text.ansi().to_string()
        } else {
            text.to_string()
        };
        eprintln!("{}", text.trim_end());
        return ExitCode::from(u8::try_from(e.exit_code()).unwrap_or(2));
    }
    let text = e.render();
    let text = if chosen.colours(Stream::Stdout) {
        text.ansi().to_string()
    } else {
        text.to_string()
    };
    output::stdout_then(text.as_bytes(), ExitCode::SUCCESS)
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

/// `ferroc lsp`: exit 0 after the client's `exit`, 1 when its input ended without one.
fn lsp(lib_path: &[PathBuf]) -> ExitCode {
    match ferroc_lsp::run_stdio(loader_options(lib_path, false)) {
        Ok(()) => ExitCode::SUCCESS,
        Err(why) => {
            eprintln!("error: {why}");
            ExitCode::from(1)
        }
    }
}

/// Loader options shared by every command that reads models.
pub(crate) fn loader_options(lib_path: &[PathBuf], allow_outside_includes: bool) -> Options {
    ferroc_host::loader_options(lib_path, allow_outside_includes)
}
