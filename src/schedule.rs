//! `ferroc schedule`: the static order each thread container executes.

use ferroc_compiler::ir::{Application, ElementKind};
use ferroc_compiler::schedule::{self, Step, StepSet};
use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(clap::Args)]
pub struct ScheduleArgs {
    /// The application model
    model: PathBuf,
    /// Extra folders searched for `NAME.lib.xml` manifests (also FERROC_LIB_PATH)
    #[arg(long, value_name = "DIR")]
    lib_path: Vec<PathBuf>,
}

pub fn run(args: ScheduleArgs) -> ExitCode {
    let result = match crate::check_first::without_errors(&args.model, &args.lib_path) {
        Ok(r) => r,
        Err(code) => return code,
    };
    let Some(app) = result.app.as_ref() else {
        return ExitCode::from(1);
    };
    let text = render(app, &schedule::compute(app, &result.libraries));
    crate::output::stdout_then(text.as_bytes(), ExitCode::SUCCESS)
}

fn render(app: &Application, schedule: &schedule::Schedule) -> String {
    let mut out = String::new();
    let describe = |s: &Step| format!("{} ({})", app.path(s.module), s.kind.as_str());
    for c in &schedule.containers {
        let trigger = match app.element(c.thread).kind {
            ElementKind::Thread {
                period: Some(p), ..
            } => format!("every {}", human_seconds(p)),
            ElementKind::Thread {
                continuous: true, ..
            } => "continuously (cycles back to back)".to_string(),
            _ => "triggered by data".to_string(),
        };
        let _ = writeln!(out, "{} — {trigger}", app.path(c.thread));
        if c.steps.is_empty() {
            let _ = writeln!(out, "  (no steps)");
        }
        for (i, step) in c.steps.iter().enumerate() {
            let set = match step.set {
                StepSet::Initial => "initial",
                StepSet::Sense => "sense",
                StepSet::Control => "control",
                StepSet::Other => "other",
            };
            let _ = writeln!(out, "  {:>3}. [{set:<7}] {}", i + 1, describe(step));
        }
        for b in &c.broken {
            let why = if b.inhibition {
                "inhibition, expected"
            } else {
                "loop, see S101"
            };
            let _ = writeln!(
                out,
                "       loop broken: {} reads {} from the previous cycle ({why})",
                describe(&b.to),
                describe(&b.from)
            );
        }
    }
    out
}

fn human_seconds(s: f64) -> String {
    if s >= 1.0 {
        format!("{s} s")
    } else if s >= 1e-3 {
        format!("{} ms", (s * 1e6).round() / 1e3)
    } else {
        format!("{} µs", (s * 1e9).round() / 1e3)
    }
}
