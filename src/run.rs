//! `ferroc run`: check a model, build it in the runtime, run it, stop cleanly.

use ferroc_compiler::library::LibrarySet;
use ferroc_compiler::plan::{self, Plan};
use ferroc_compiler::report::json::location;
use ferroc_compiler::schedule::StepKind as PlanStep;
use ferroc_compiler::source::{SourceMap, Span};
use ferroc_compiler::values::Value as ModelValue;
use ferroc_runtime::behaviour::ViolationPolicy;
use ferroc_runtime::builder::{
    Builder, Conversion, ModuleSpec, Registry, RunningApp, Schedule, StepKind, ThreadSpec,
};
use ferroc_runtime::container::ThreadOptions;
use ferroc_runtime::module::Value;
use ferroc_runtime::port::{ConnectOptions, OnFull, QueueConfig};
use std::io::{IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

#[derive(clap::Args)]
pub struct RunArgs {
    /// The application model
    model: PathBuf,
    /// Stop after this long: `10s`, `500ms`, `2min`
    #[arg(long = "for", value_name = "DURATION", value_parser = parse_duration)]
    duration: Option<Duration>,
    /// Stop after this many cycles of every thread container
    #[arg(long, value_name = "N")]
    cycles: Option<u64>,
    /// A value for a parameter declared with `cmdline=NAME` (repeatable)
    #[arg(long = "param", value_name = "NAME=VALUE")]
    params: Vec<String>,
    /// No live status line
    #[arg(long, short)]
    quiet: bool,
    /// Extra folders searched for `NAME.lib.xml` manifests (also FERROC_LIB_PATH)
    #[arg(long, value_name = "DIR")]
    lib_path: Vec<PathBuf>,
}

fn parse_duration(text: &str) -> Result<Duration, String> {
    let seconds = ferroc_compiler::values::parse_duration(text)
        .map_err(|_| format!("`{text}` is not a duration; write e.g. 10s, 500ms or 2min"))?;
    if !(0.0..=1e9).contains(&seconds) {
        return Err(format!("`{text}` is out of range"));
    }
    Ok(Duration::from_secs_f64(seconds))
}

/// Every module type this binary can run.
pub fn registry() -> Registry {
    let mut registry = Registry::new();
    ferroc_std::register(&mut registry);
    crash_course::register(&mut registry);
    nav_behaviours::register(&mut registry);
    registry
}

pub fn run(args: RunArgs) -> ExitCode {
    let mut cmdline = Vec::new();
    for p in &args.params {
        match p.split_once('=') {
            Some((name, value)) if !name.trim().is_empty() => {
                cmdline.push((name.trim().to_string(), value.trim().to_string()))
            }
            _ => {
                eprintln!("error: --param {p}: write NAME=VALUE, e.g. --param front-noise=5cm");
                return ExitCode::from(2);
            }
        }
    }
    let result = match crate::checked::without_errors(&args.model, &args.lib_path) {
        Ok(r) => r,
        Err(code) => return code,
    };
    let Some(app) = result.app.as_ref() else {
        return ExitCode::from(1);
    };
    let (plan, unsupported) = plan::plan(app, &result.libraries, &cmdline);
    for p in &unsupported {
        eprintln!("{}: error: {}", at(&result.sources, p.span), p.what);
    }
    let registry = registry();
    let agree = interfaces_agree(&plan, &registry, &result.libraries, &result.sources);
    if let Err(lines) = &agree {
        for line in lines {
            eprintln!("{line}");
        }
    }
    if !unsupported.is_empty() || agree.is_err() {
        return ExitCode::from(1);
    }
    // Before any thread starts, so that a signal never finds the default handler.
    let interrupted = Arc::new(AtomicBool::new(false));
    let flag = interrupted.clone();
    if let Err(e) = ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst)) {
        eprintln!("warning: Ctrl-C will not stop cleanly: {e}");
    }
    let app = match build(&plan, &registry, args.cycles) {
        Ok(app) => app,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(1);
        }
    };
    for w in app.warnings() {
        eprintln!("warning: {w}");
    }
    let status = !args.quiet && std::io::stderr().is_terminal();
    supervise(app, &interrupted, args.duration, status)
}

fn at(sources: &SourceMap, span: Span) -> String {
    let l = location(sources, span);
    format!(
        "{}:{}:{}",
        l["file"].as_str().unwrap_or("?"),
        l["line"],
        l["column"]
    )
}

/// Refuses to run a module type whose Rust interface differs from its manifest.
fn interfaces_agree(
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
            lines.push(format!(
                "{}: error: the module type `{}` of `{}` is not built into this ferroc binary\n  \
                 help: registered types: {}",
                at(sources, m.span),
                m.type_name,
                m.path,
                registry.names().collect::<Vec<_>>().join(", ")
            ));
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

fn value(v: &ModelValue) -> Value {
    match v {
        ModelValue::Bool(b) => Value::Bool(*b),
        ModelValue::Int(i) => Value::Int(*i),
        ModelValue::Float(x) => Value::Float(*x),
        ModelValue::Str(s) | ModelValue::Opaque(s) => Value::Text(s.clone()),
        ModelValue::Duration(s) => Value::Duration(Duration::from_secs_f64(s.max(0.0))),
        ModelValue::List(items) => Value::List(items.iter().map(value).collect()),
    }
}

/// The Builder calls for a plan (the bundle writes the same calls as source).
pub fn build(
    plan: &Plan,
    registry: &Registry,
    cycles: Option<u64>,
) -> Result<RunningApp, ferroc_runtime::builder::BuildError> {
    let mut builder = Builder::new(registry);
    for m in &plan.modules {
        let params: Vec<(String, Value)> = m
            .params
            .iter()
            .map(|(n, v)| (n.clone(), value(v)))
            .collect();
        let queues: Vec<(String, QueueConfig)> = m
            .queues
            .iter()
            .map(|(port, n, policy)| {
                let on_full = match policy.as_str() {
                    "drop-oldest" => OnFull::DropOldest,
                    "drop-newest" => OnFull::DropNewest,
                    _ => OnFull::Block,
                };
                (port.clone(), QueueConfig::new(*n as usize).on_full(on_full))
            })
            .collect();
        builder.add_module(ModuleSpec {
            path: &m.path,
            type_name: &m.type_name,
            params: &params,
            queues: &queues,
            violations: ViolationPolicy::parse(&m.ib2c_violations).unwrap_or_default(),
        })?;
    }
    for c in &plan.connections {
        builder.connect(
            (&c.from.0, &c.from.1),
            (&c.to.0, &c.to.1),
            Conversion {
                scale: c.scale,
                offset: c.offset,
            },
            ConnectOptions::default(),
        )?;
    }
    for t in &plan.threads {
        builder.add_thread(ThreadSpec {
            path: t.path.clone(),
            schedule: match t.period {
                Some(p) => Schedule::Periodic(Duration::from_secs_f64(p)),
                None => Schedule::Data,
            },
            options: ThreadOptions::default(),
            steps: t
                .steps
                .iter()
                .map(|(path, kind)| {
                    let kind = match kind {
                        PlanStep::Update => StepKind::Update,
                        PlanStep::Sense => StepKind::Sense,
                        PlanStep::Control => StepKind::Control,
                    };
                    (path.clone(), kind)
                })
                .collect(),
        })?;
    }
    builder.start(cycles)
}

/// Runs until the cycle limit, `--for`, Ctrl-C or SIGTERM; shows a status line on a
/// terminal; reports panics. Exit code 1 if a module panicked.
fn supervise(
    mut app: RunningApp,
    interrupted: &AtomicBool,
    duration: Option<Duration>,
    status: bool,
) -> ExitCode {
    ferroc_runtime::console::set_status_line_active(status);
    let started = Instant::now();
    let mut last_draw = Instant::now() - Duration::from_secs(1);
    let mut reported_panics = 0;
    let reason = loop {
        if app.is_finished() {
            break "cycle limit reached";
        }
        if interrupted.load(Ordering::SeqCst) {
            break "interrupted";
        }
        if duration.is_some_and(|d| started.elapsed() >= d) {
            break "time is up";
        }
        let panics = app.panics();
        for p in &panics[reported_panics..] {
            ferroc_runtime::console::line(&format!("error: {p}"));
        }
        reported_panics = panics.len();
        report_violations(&app);
        if status && last_draw.elapsed() >= Duration::from_millis(250) {
            last_draw = Instant::now();
            let line = status_line(&app, started.elapsed());
            let _ = write!(std::io::stderr(), "\r\x1b[K{line}");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    app.stop();
    app.join();
    ferroc_runtime::console::set_status_line_active(false);
    if status {
        eprint!("\r\x1b[K");
    }
    report_violations(&app);
    let panics = app.panics();
    for p in &panics[reported_panics.min(panics.len())..] {
        eprintln!("error: {p}");
    }
    eprintln!(
        "stopped ({reason}) after {:.1} s",
        started.elapsed().as_secs_f64()
    );
    for s in app.status() {
        eprintln!(
            "  {}: {} cycles, {} overruns, load {:.1} %",
            s.path,
            s.cycles,
            s.overruns,
            s.load * 100.0
        );
    }
    let violations = app.violation_counts();
    if !violations.is_empty() {
        eprintln!("iB2C principle violations:");
        for v in &violations {
            eprintln!(
                "  {}: {} × {} (policy {})",
                v.path,
                v.count,
                v.rule.name(),
                v.policy.as_str()
            );
        }
        let dropped = app.violation_reports_dropped();
        if dropped > 0 {
            eprintln!("  ({dropped} reports were dropped unread)");
        }
    }
    if panics.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}

/// Prints the iB2C violation reports made since the last call (each already
/// rate-limited by its module's policy).
fn report_violations(app: &RunningApp) {
    for r in app.take_violation_reports() {
        ferroc_runtime::console::line(&format!("warning: {r}"));
    }
}

fn status_line(app: &RunningApp, elapsed: Duration) -> String {
    let mut line = format!("{:>6.1} s", elapsed.as_secs_f64());
    for s in app.status() {
        let name = s.path.rsplit('/').next().unwrap_or(&s.path);
        line.push_str(&format!(
            " | {name}: {} cycles, {} overruns, load {:.0} %",
            s.cycles,
            s.overruns,
            s.load * 100.0
        ));
    }
    line
}
