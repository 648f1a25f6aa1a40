//! `ferroc run`: check a model, build it in the runtime, run it, stop cleanly.

pub use crate::spec::{params_of, ports_of, queues_of, step_kind};

mod from_plan;
use ferroc_compiler::library::LibrarySet;
use ferroc_compiler::plan::{self, Plan};
use ferroc_compiler::report::json::location;
use ferroc_compiler::source::{SourceMap, Span};
use ferroc_compiler::CheckResult;
use ferroc_runtime::behaviour::ViolationPolicy;
use ferroc_runtime::builder::{
    Builder, Conversion, Lockstep, ModuleSpec, Registry, RunningApp, Schedule, StartOptions,
    ThreadSpec,
};
use ferroc_runtime::link::CallSpec;
use ferroc_runtime::port::ConnectOptions;
use ferroc_runtime::supervise;
use from_plan::conversion;
pub(crate) use from_plan::value;
pub use from_plan::{link_spec, thread_options};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
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
    lockstep: bool,
    /// A value for a parameter declared with `cmdline=NAME` (repeatable)
    #[arg(long = "param", value_name = "NAME=VALUE")]
    params: Vec<String>,
    /// No live status line
    #[arg(long, short)]
    quiet: bool,
    /// Extra folders searched for `NAME.lib.xml` manifests (also FERROC_LIB_PATH)
    #[arg(long, value_name = "DIR")]
    pub lib_path: Vec<PathBuf>,
    /// Where loggers' relative file paths lie (default: FERROC_LOG_DIR, else the
    /// working directory); absolute paths in the model are kept
    #[arg(long, value_name = "DIR")]
    pub log_dir: Option<PathBuf>,
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
    let mut registry = Registry::new();
    ferroc_std::register(&mut registry);
    registry
}

/// The `--param NAME=VALUE` pairs, or the exit code of a malformed one (reported).
pub fn cmdline_params(args: &RunArgs) -> Result<Vec<(String, String)>, ExitCode> {
    let mut cmdline = Vec::new();
    for p in &args.params {
        match p.split_once('=') {
            Some((name, value)) if !name.trim().is_empty() => {
                cmdline.push((name.trim().to_string(), value.trim().to_string()))
            }
            _ => {
                eprintln!("error: --param {p}: write NAME=VALUE, e.g. --param front-noise=5cm");
                return Err(ExitCode::from(2));
            }
        }
    }
    Ok(cmdline)
}

/// `ferroc run` with the module types of `registry`: check, plan, build, supervise.
pub fn run(args: RunArgs, registry: &Registry) -> ExitCode {
    if let Err(code) = cmdline_params(&args) {
        return code;
    }
    let result = match crate::checked::without_errors(&args.model, &args.lib_path) {
        Ok(r) => r,
        Err(code) => return code,
    };
    run_checked(args, &result, registry)
}

/// `ferroc run` of a model checked without errors.
pub fn run_checked(args: RunArgs, result: &CheckResult, registry: &Registry) -> ExitCode {
    let cmdline = match cmdline_params(&args) {
        Ok(c) => c,
        Err(code) => return code,
    };
    let Some(app) = result.app.as_ref() else {
        return ExitCode::from(1);
    };
    let accepted: std::collections::BTreeSet<&str> = app
        .modules()
        .flat_map(|(_, m)| m.params.iter())
        .filter_map(|p| p.cmdline.as_ref().map(|(n, _)| n.as_str()))
        .collect();
    for (name, _) in &cmdline {
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
            return ExitCode::from(2);
        }
    }
    let (mut plan, unsupported) = plan::plan(app, &result.libraries, &cmdline);
    for p in &unsupported {
        eprintln!("{}: error: {}", at(&result.sources, p.span), p.what);
    }
    crate::record::configure(app, &plan, args.log_dir.clone());
    // `--record` adds a recorder type: to a copy, the caller's registry stays as it is.
    let mut registry = registry.clone();
    let agree = interfaces_agree(&plan, &registry, &result.libraries, &result.sources);
    if let Err(lines) = &agree {
        for line in lines {
            eprintln!("{line}");
        }
    }
    if !unsupported.is_empty() || agree.is_err() {
        return ExitCode::from(1);
    }
    if let Some(file) = &args.record {
        let added =
            crate::record::add_recorders(&mut plan, &mut registry, file, &args.record_filter);
        if let Err(e) = added {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    }
    // Before any thread starts, so that a signal never finds the default handler.
    let interrupted = Arc::new(AtomicBool::new(false));
    let flag = interrupted.clone();
    if let Err(e) = ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst)) {
        eprintln!("warning: Ctrl-C will not stop cleanly: {e}");
    }
    let start = StartOptions {
        limit: args.cycles,
        lockstep: args.lockstep.then(|| Lockstep {
            periods: Vec::new(),
            until: args.duration,
        }),
        network: None,
    };
    let serve = args
        .inspect
        .as_deref()
        .map(|address| crate::inspect::Serve {
            address,
            public: args.inspect_public,
            app: &app.name,
        });
    if let Some(Err(e)) = serve.as_ref().map(crate::inspect::check_address) {
        eprintln!("error: {e}");
        return ExitCode::from(2);
    }
    let started = wire(&plan, &registry).and_then(|mut builder| match serve {
        // Inspected: the structure stays changeable while it runs (edits).
        Some(_) => {
            let catalogue = builder.inspection();
            builder
                .start_live(start)
                .map(|(app, live)| (app, Some((catalogue, live))))
        }
        None => builder.start_with(start).map(|app| (app, None)),
    });
    let (app, inspection) = match started {
        Ok(started) => started,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(1);
        }
    };
    // Kept until the run ends: dropping it stops serving.
    let _server = match (&serve, inspection) {
        (Some(serve), Some((catalogue, live))) => {
            let running = crate::edit::Running {
                model: args.model.clone(),
                text: model_text(&args.model, &result.sources),
                lib_path: args.lib_path.clone(),
                cmdline: cmdline.clone(),
                plan: plan.clone(),
                live,
                off: args.record.as_ref().map(|_| {
                    "this run records (--record): its recorders are not in the model, so its structure does not change; run without --record to edit".to_string()
                }),
            };
            match crate::inspect::start(serve, catalogue, &app, result, &registry, running) {
                Ok(server) => Some(server),
                Err(e) => {
                    eprintln!("error: --inspect: {e}");
                    return ExitCode::from(1);
                }
            }
        }
        _ => None,
    };
    let options = supervise::Options {
        duration: args.duration.filter(|_| !args.lockstep),
        status_line: !args.quiet && std::io::stderr().is_terminal(),
    };
    supervise::supervise(app, &interrupted, &options)
}

/// The text of the model file as it was checked.
fn model_text(model: &std::path::Path, sources: &SourceMap) -> String {
    let canonical = model.canonicalize().unwrap_or_else(|_| model.to_path_buf());
    let file = sources
        .find(&canonical)
        .unwrap_or(ferroc_compiler::source::FileId(0));
    sources.get(file).text.clone()
}

/// `FILE:LINE:COL` of a span.
pub fn at(sources: &SourceMap, span: Span) -> String {
    let l = location(sources, span);
    format!(
        "{}:{}:{}",
        l["file"].as_str().unwrap_or("?"),
        l["line"],
        l["column"]
    )
}

/// Refuses to run a module type whose Rust interface differs from its manifest.
pub fn interfaces_agree(
    plan: &Plan,
    registry: &Registry,
    libs: &LibrarySet,
    sources: &SourceMap,
) -> Result<(), Vec<String>> {
    let mut lines = Vec::new();
    let mut seen = std::collections::HashSet::new();
    for m in &plan.modules {
        if !seen.insert(m.type_name.as_str()) {
            continue;
        }
        let Some(code) = registry.interface(&m.type_name) else {
            lines.push(not_registered(m, registry, libs, sources));
            continue;
        };
        let Some((_, manifest)) = libs.module_type(&m.type_name) else {
            continue;
        };
        let differences = crate::interface::differences(manifest, &code);
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
    registry: &Registry,
    libs: &LibrarySet,
    sources: &SourceMap,
) -> String {
    let (library, rust) = match libs.module_type(&m.type_name) {
        Some((id, t)) => (Some(libs.get(id)), t.rust.as_str()),
        None => (None, "the Rust type"),
    };
    let prefix = library.map(|l| format!("{}.", l.name)).unwrap_or_default();
    let mut same_library: Vec<&str> = registry
        .names()
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
            registry.names().collect::<Vec<_>>().join(", ")
        ),
    }
}

/// The Builder calls for a plan (the bundle writes the same calls as source). Every
/// part runs in this process; connections between parts still travel as links (their
/// values encoded, paced by their `sharing=`), as they will between programs.
pub fn build(
    plan: &Plan,
    registry: &Registry,
    start: StartOptions,
) -> Result<RunningApp, ferroc_runtime::builder::BuildError> {
    wire(plan, registry)?.start_with(start)
}

/// The Builder calls of [`build`] up to the start: every module, connection, call and
/// thread container declared.
pub fn wire<'r>(
    plan: &Plan,
    registry: &'r Registry,
) -> Result<Builder<'r>, ferroc_runtime::builder::BuildError> {
    let mut builder = Builder::new(registry);
    for m in &plan.modules {
        let (params, queues, ports) = (params_of(m), queues_of(m), ports_of(m));
        builder.add_module(ModuleSpec {
            path: &m.path,
            type_name: &m.type_name,
            params: &params,
            queues: &queues,
            ports: &ports,
            violations: ViolationPolicy::parse(&m.ib2c_violations).unwrap_or_default(),
        })?;
    }
    for (name, level, recursive) in &plan.locks.resources {
        builder.add_resource(name, *level, *recursive)?;
    }
    for (path, slot, resource) in &plan.locks.binds {
        builder.bind_lock(path, slot, resource)?;
    }
    for (first, second, why) in &plan.locks.orders {
        // A slot without <bind> or <resource> names its own resource.
        for name in [first, second] {
            if !plan.locks.resources.iter().any(|(r, _, _)| r == name) {
                let _ = builder.add_resource(name, None, false);
            }
        }
        builder.declare_lock_order(first, second, why)?;
    }
    for c in &plan.connections {
        let (from, to) = (
            (c.from.0.as_str(), c.from.1.as_str()),
            (c.to.0.as_str(), c.to.1.as_str()),
        );
        match &c.link {
            None => {
                let options = ConnectOptions::default().with_local(c.local);
                builder.connect(from, to, conversion(c), options)?
            }
            Some(link) => {
                let spec = link_spec(link);
                builder.link_out(&spec, from, conversion(c))?;
                builder.link_in(&spec, to, ConnectOptions::default())?;
            }
        }
    }
    for link in &plan.param_links {
        let (from, to) = (
            (link.from.0.as_str(), link.from.1.as_str()),
            (link.to.0.as_str(), link.to.1.as_str()),
        );
        let scale = Conversion::linear(link.scale, 0.0);
        match &link.link {
            None => builder.connect_param(from, to, scale)?,
            Some(between) => {
                let spec = link_spec(between);
                builder.link_out(&spec, from, scale)?;
                builder.link_in_param(&spec, to)?;
            }
        }
    }
    for call in &plan.calls {
        let (client, service) = (
            (call.client.0.as_str(), call.client.1.as_str()),
            (call.service.0.as_str(), call.service.1.as_str()),
        );
        match &call.link {
            // Between parts, as between the bundle's programs; types the libraries
            // did not register for crossing are called directly (one process).
            Some(link) if builder.can_call_across(client) => {
                let service_key = format!("{}/{}", service.0, service.1);
                let spec = CallSpec {
                    id: link.id,
                    client_part: &link.client_part,
                    server_part: &link.server_part,
                    service: &service_key,
                };
                builder.call_out(&spec, client)?;
                builder.call_in(&spec, service)?;
            }
            _ => builder.connect_service(client, service)?,
        }
    }
    for t in &plan.threads {
        builder.add_thread(ThreadSpec {
            path: t.path.clone(),
            schedule: match (t.period, t.continuous) {
                (Some(p), _) => Schedule::Periodic(Duration::from_secs_f64(p)),
                (None, true) => Schedule::Continuous,
                (None, false) => Schedule::Data,
            },
            options: thread_options(t),
            steps: t
                .steps
                .iter()
                .map(|(path, kind)| (path.clone(), step_kind(kind)))
                .collect(),
        })?;
    }
    Ok(builder)
}
