//! `ferroc run`: check a model, plan it, compare the manifests with the module types'
//! code, and run the plan (`ferroc_runner`), here or in a runner.

use crate::inspect::Serve;
use crate::sources::{at, model_text};
use ferroc_compiler::ir::Application;
use ferroc_compiler::library::LibrarySet;
use ferroc_compiler::plan::{self, Plan};
use ferroc_compiler::source::SourceMap;
use ferroc_compiler::CheckResult;
use ferroc_runner::plan::{RunOptions, RunPlan};
use ferroc_runner::run::Ros2Network;
use ferroc_runtime::builder::{BuildError, Live, Registry, RunningApp, StartOptions};
use ferroc_runtime::inspect::Catalogue;
use ferroc_runtime::module::Interface;
use ferroc_runtime::supervise;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

#[derive(clap::Args)]
pub struct RunArgs {
    /// The application model
    pub model: PathBuf,
    /// Stop after this long: `10s`, `500ms`, `2min` (each thread container stops after
    /// the cycle it is in, a sleeping one at once; with --lockstep: this much model
    /// time, however long it takes to compute)
    #[arg(long = "for", value_name = "DURATION", value_parser = parse_duration)]
    duration: Option<Duration>,
    /// Stop after N cycles of the application: N cycles of its fastest periodic thread
    /// containers (those with the shortest period); slower containers run until then
    /// (in lockstep exactly the instants before N times the shortest period)
    #[arg(long, value_name = "N")]
    cycles: Option<u64>,
    /// Run in simulated time on one thread: every periodic container at its instants
    /// of model time, links between parts delivering at the next instant. The output
    /// is the same on every run, and the same as the bundle's programs with
    /// `--lockstep` (use with --cycles, or --for in model time)
    #[arg(long)]
    pub lockstep: bool,
    /// The run seed every module's random source is derived from, with the module's
    /// path: the same seed gives the same numbers (default: chosen at random and
    /// printed at start, so that a run can be repeated)
    #[arg(long, value_name = "N", value_parser = supervise::parse_seed)]
    seed: Option<u64>,
    /// A value for a parameter declared with `cmdline=NAME` (repeatable)
    #[arg(long = "param", value_name = "NAME=VALUE")]
    params: Vec<String>,
    /// No live status line
    #[arg(long, short)]
    quiet: bool,
    /// Show cargo's own output while the runner of the model's libraries is built
    /// (without it: one line saying what is built and why, then the time it took)
    #[arg(long, short)]
    pub verbose: bool,
    /// Extra folders searched for `NAME.lib.xml` manifests (also FERROC_LIB_PATH)
    #[arg(long, value_name = "DIR")]
    pub lib_path: Vec<PathBuf>,
    /// Where loggers write (default: FERROC_LOG_DIR, else the working directory):
    /// their relative paths lie under it, and an absolute path in the model must lead
    /// into it
    #[arg(long, value_name = "DIR")]
    pub log_dir: Option<PathBuf>,
    /// Let --record and loggers replace an existing file that is not a ferroc
    /// recording (without it, such a file is never overwritten)
    #[arg(long)]
    pub force: bool,
    /// Record every connection between modules into this MCAP file (relative to the
    /// working directory), without editing the model; read it with `ferroc log`
    #[arg(long, value_name = "FILE")]
    pub record: Option<PathBuf>,
    /// With --record: only outputs whose path (`module/port`) matches; `*` matches
    /// any characters (repeatable)
    #[arg(long, value_name = "PATTERN", requires = "record")]
    pub record_filter: Vec<String>,
    /// Serve live inspection over Zenoh on ADDR (default 127.0.0.1:47900): read it with
    /// `ferroc inspect`; changes need the token printed at start (docs/inspect.md)
    #[arg(long, value_name = "ADDR", num_args = 0..=1, default_missing_value = "127.0.0.1:47900")]
    pub inspect: Option<String>,
    /// Allow --inspect on an address other computers can reach (prints a warning)
    #[arg(long, requires = "inspect")]
    pub inspect_public: bool,
    /// The summary at the end: human (on standard error), or also json: one line on
    /// standard output after the run (docs/run-summary.md)
    #[arg(long, value_enum, default_value_t = Format::Human)]
    pub format: Format,
}

/// How `ferroc run` reports its end.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// The summary on standard error
    #[default]
    Human,
    /// Also one line of JSON on standard output (docs/run-summary.md)
    Json,
}

fn parse_duration(text: &str) -> Result<Duration, String> {
    let seconds = ferroc_compiler::values::parse_duration(text)
        .map_err(|_| format!("`{text}` is not a duration; write e.g. 10s, 500ms or 2min"))?;
    if !(0.0..=1e9).contains(&seconds) {
        return Err(format!("`{text}` is out of range"));
    }
    Ok(Duration::from_secs_f64(seconds))
}

/// The module types built into `ferroc` itself: the standard library's. A runner adds
/// those of the libraries it links.
pub fn registry() -> Registry {
    ferroc_runner::registry()
}

/// The interfaces of registered module types by name: what manifests are compared with
/// (a runner's come from its `describe`).
pub type Interfaces = BTreeMap<String, Interface>;

/// The interfaces of every type of `registry`.
pub fn interfaces_of(registry: &Registry) -> Interfaces {
    Interfaces::from_iter(interface_list(ferroc_runner::interfaces(registry)))
}

/// `list` keyed by type name.
pub fn interface_list(list: Vec<Interface>) -> impl Iterator<Item = (String, Interface)> {
    list.into_iter().map(|i| (i.name.clone(), i))
}

/// The `--param NAME=VALUE` pairs, or the exit code of a malformed one (reported).
pub fn cmdline_params(args: &RunArgs) -> Result<Vec<(String, String)>, ExitCode> {
    param_pairs(&args.params).map_err(|e| {
        eprintln!("error: {e}");
        ExitCode::from(2)
    })
}

/// `--param NAME=VALUE` arguments as (name, value), trimmed: the one reading of them,
/// for `ferroc run` and `ferroc bundle`. The error names the malformed argument.
pub fn param_pairs(params: &[String]) -> Result<Vec<(String, String)>, String> {
    params
        .iter()
        .map(|p| match p.split_once('=') {
            Some((name, value)) if !name.trim().is_empty() => {
                Ok((name.trim().to_string(), value.trim().to_string()))
            }
            _ => Err(format!(
                "--param {p}: write NAME=VALUE, e.g. --param front-noise=5cm"
            )),
        })
        .collect()
}

/// `ferroc run` with the module types of `registry`: check, plan, build, supervise.
pub fn run(args: RunArgs, registry: &Registry) -> ExitCode {
    run_with(args, registry, None)
}

/// [`run`], with `ros2` opening the network of the model's ROS 2 nodes (the runner of
/// a model with `<ros2>`; without it such a model is refused when it starts).
pub fn run_with(args: RunArgs, registry: &Registry, ros2: Option<Ros2Network>) -> ExitCode {
    if let Err(code) = cmdline_params(&args) {
        return code;
    }
    let result =
        match crate::check_first::without_errors_as(&args.model, &args.lib_path, args.lockstep) {
            Ok(r) => r,
            Err(code) => return code,
        };
    run_checked_with(args, &result, registry, ros2)
}

/// `ferroc run` of a model checked without errors, in this process.
pub fn run_checked(args: RunArgs, result: &CheckResult, registry: &Registry) -> ExitCode {
    run_checked_with(args, result, registry, None)
}

/// [`run_checked`], with `ros2` opening the network of the model's ROS 2 nodes.
fn run_checked_with(
    args: RunArgs,
    result: &CheckResult,
    registry: &Registry,
    ros2: Option<Ros2Network>,
) -> ExitCode {
    let (plan, run_plan) = match plan_run(&args, result, &interfaces_of(registry)) {
        Ok(planned) => planned,
        Err(code) => return code,
    };
    if args.inspect.is_none() {
        return ferroc_runner::run::run_with(run_plan, registry, ros2);
    }
    run_inspected(args, result, (plan, run_plan), registry, ros2)
}

/// The run plan a runner is handed (and the compiler's plan it came from): the
/// `--param`s known, nothing the runtime cannot realise, every module type used
/// registered with the interface its manifest declares (`interfaces`: the types the
/// runner registers); else the problems are reported and the exit code given.
pub fn plan_run(
    args: &RunArgs,
    result: &CheckResult,
    interfaces: &Interfaces,
) -> Result<(Plan, RunPlan), ExitCode> {
    let cmdline = cmdline_params(args)?;
    let Some(app) = result.app.as_ref() else {
        return Err(ExitCode::from(1));
    };
    refuse_unknown_params(args, app, &cmdline)?;
    let (plan, unsupported) = plan::plan(app, &result.libraries, &cmdline);
    for p in &unsupported {
        eprintln!("{}: error: {}", at(&result.sources, p.span), p.what);
    }
    let agree = interfaces_agree(&plan, interfaces, &result.libraries, &result.sources);
    if let Err(lines) = &agree {
        for line in lines {
            eprintln!("{line}");
        }
    }
    if !unsupported.is_empty() || agree.is_err() {
        return Err(ExitCode::from(1));
    }
    if args.lockstep {
        crate::check_first::print_lockstep_findings(result);
    }
    let mut run_plan = crate::from_plan::run_plan(&plan, app);
    run_plan.seed = args.seed.or(app.seed);
    run_plan.run = RunOptions {
        duration: args.duration,
        cycles: args.cycles,
        lockstep: args.lockstep,
        quiet: args.quiet,
        log_dir: args.log_dir.clone(),
        force: args.force,
        record: args.record.clone(),
        record_filter: args.record_filter.clone(),
        format_json: args.format == Format::Json,
    };
    Ok((plan, run_plan))
}

/// `ferroc run --inspect`: the run of [`ferroc_runner::run::run`] with the inspection
/// server and structural edits (which check the edited model: the compiler is here).
fn run_inspected(
    args: RunArgs,
    result: &CheckResult,
    (plan, mut run_plan): (Plan, RunPlan),
    registry: &Registry,
    ros2: Option<Ros2Network>,
) -> ExitCode {
    let Some(app) = result.app.as_ref() else {
        return ExitCode::from(1);
    };
    let serve = Serve {
        address: args.inspect.as_deref().unwrap_or_default(),
        public: args.inspect_public,
        app: &app.name,
    };
    if let Err(e) = crate::inspect::check_address(&serve) {
        eprintln!("error: {e}");
        return ExitCode::from(2);
    }
    let registry = match ferroc_runner::run::prepare(&mut run_plan, registry) {
        Ok(r) => r,
        Err(code) => return code,
    };
    let seed = ferroc_runner::run::seed(&run_plan);
    let interrupted = ferroc_runner::run::interrupt_flag();
    let mut start = ferroc_runner::run::start_options(&run_plan.run);
    // The nodes open their own Zenoh session (rmw_zenoh's configuration, e.g. the
    // router's address); the inspection server keeps its loopback-only one.
    if let (false, Some(network)) = (run_plan.ros2.is_empty(), ros2) {
        match network() {
            Ok(n) => start.network = Some(n),
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::from(2);
            }
        }
    }
    let (running, catalogue, live) = match start_live(&run_plan, &registry, seed, start) {
        Ok(started) => started,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(1);
        }
    };
    // Kept until the run ends: dropping it stops serving.
    let cmdline = cmdline_params(&args).unwrap_or_default();
    let running_model = editable(&args, result, &cmdline, &plan, live);
    let started = crate::inspect::start(
        &serve,
        catalogue,
        &running,
        result,
        &registry,
        running_model,
    );
    let _server = match started {
        Ok(server) => server,
        Err(e) => {
            eprintln!("error: --inspect: {e}");
            return ExitCode::from(1);
        }
    };
    let options = ferroc_runner::run::supervise_options(&run_plan.run);
    let (code, summary) = supervise::supervise_summarised(running, &interrupted, &options);
    ferroc_runner::summary::finish(&run_plan, seed, &summary, code)
}

/// What structural edits of the running application (`--inspect`) start from: its
/// model text, how it was planned, and its live handle; refused while it records.
fn editable(
    args: &RunArgs,
    result: &CheckResult,
    cmdline: &[(String, String)],
    plan: &Plan,
    live: Live,
) -> crate::edit::Running {
    crate::edit::Running {
        model: args.model.clone(),
        text: model_text(&args.model, &result.sources),
        lib_path: args.lib_path.clone(),
        cmdline: cmdline.to_vec(),
        plan: plan.clone(),
        live,
        off: args.record.as_ref().map(|_| {
            "this run records (--record): its recorders are not in the model, so its structure does not change; run without --record to edit".to_string()
        }),
    }
}

/// Refuses (exit code 2) a `--param` no parameter of the model is declared with.
fn refuse_unknown_params(
    args: &RunArgs,
    app: &Application,
    cmdline: &[(String, String)],
) -> Result<(), ExitCode> {
    let accepted: std::collections::BTreeSet<&str> = app
        .modules()
        .flat_map(|(_, m)| m.params.iter())
        .filter_map(|p| p.cmdline.as_ref().map(|(n, _)| n.as_str()))
        .collect();
    for (name, _) in cmdline {
        if !accepted.contains(name.as_str()) {
            eprintln!(
                "error: --param {name}: no parameter of {} is declared with cmdline=\"{name}\"\n  help: {}",
                args.model.display(),
                if accepted.is_empty() {
                    "this model takes no command-line parameters".to_string()
                } else {
                    format!("it accepts: {}", accepted.iter().copied().collect::<Vec<_>>().join(", "))
                }
            );
            return Err(ExitCode::from(2));
        }
    }
    Ok(())
}

/// Builds and starts the application with its structure changeable while it runs
/// (edits); its inspection catalogue and live handle come along.
fn start_live(
    plan: &RunPlan,
    registry: &Registry,
    seed: u64,
    start: StartOptions,
) -> Result<(RunningApp, Catalogue, Live), BuildError> {
    let mut builder = ferroc_runner::build::builder(plan, registry, seed)?;
    let catalogue = builder.inspection();
    let (app, live) = builder.start_live(start)?;
    Ok((app, catalogue, live))
}

/// Refuses to run a module type whose Rust interface differs from its manifest.
pub fn interfaces_agree(
    plan: &Plan,
    registry: &Interfaces,
    libs: &LibrarySet,
    sources: &SourceMap,
) -> Result<(), Vec<String>> {
    let mut lines = Vec::new();
    let mut seen = std::collections::HashSet::new();
    for m in &plan.modules {
        if !seen.insert(m.type_name.as_str()) {
            continue;
        }
        let Some(code) = registry.get(&m.type_name) else {
            lines.push(not_registered(m, registry, libs, sources));
            continue;
        };
        let Some((_, manifest)) = libs.module_type(&m.type_name) else {
            continue;
        };
        let differences = crate::interface::differences(manifest, code);
        if !differences.is_empty() {
            lines.push(format!(
                "{}: error: the Rust type `{}` does not implement the interface its manifest declares for `{}`:\n{}\n  \
                 help: change the Rust type or the manifest so they agree; `ferroc types export` writes the manifest the code implies",
                at(sources, manifest.span),
                code.rust,
                m.type_name,
                differences
                    .iter()
                    .map(|d| format!("  - {d}"))
                    .collect::<Vec<_>>()
                    .join("\n")
            ));
        }
    }
    if lines.is_empty() {
        Ok(())
    } else {
        Err(lines)
    }
}

/// A module type the model uses that no linked crate registers: the library's crate
/// lacks the `register` call (or the manifest names a type the crate does not have).
fn not_registered(
    m: &plan::PlannedModule,
    registry: &Interfaces,
    libs: &LibrarySet,
    sources: &SourceMap,
) -> String {
    let (library, rust) = match libs.module_type(&m.type_name) {
        Some((id, t)) => (Some(libs.get(id)), t.rust.as_str()),
        None => (None, "the Rust type"),
    };
    let prefix = library.map(|l| format!("{}.", l.name)).unwrap_or_default();
    let mut same_library: Vec<&str> = registry
        .keys()
        .map(String::as_str)
        .filter(|n| !prefix.is_empty() && n.starts_with(&prefix))
        .collect();
    same_library.sort_unstable();
    let registers = if same_library.is_empty() {
        "none of its types".to_string()
    } else {
        same_library.join(", ")
    };
    match library.and_then(|l| l.rust_crate.as_deref().map(|c| (l, c))) {
        Some((lib, krate)) if lib.name != "ferroc_std" => format!(
            "{}: error: the module type `{}` of `{}` is not registered by the crate `{krate}` of library `{}` ({})\n  \
             help: its `register` function must call `registry.register::<{rust}>()`; it registers {registers}",
            at(sources, m.span),
            m.type_name,
            m.path,
            lib.name,
            at(sources, lib.name_span),
        ),
        _ => format!(
            "{}: error: the module type `{}` of `{}` is not built into this ferroc binary\n  \
             help: registered types: {}",
            at(sources, m.span),
            m.type_name,
            m.path,
            registry.keys().cloned().collect::<Vec<_>>().join(", ")
        ),
    }
}
