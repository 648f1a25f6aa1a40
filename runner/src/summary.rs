//! `ferroc run --format json`: the run's summary as one line of JSON on standard
//! output, after the run (the human summary stays on standard error). The shape, with
//! its `version`, is documented in docs/run-summary.md.

use crate::plan::RunPlan;
use ferroc_runtime::supervise::Summary;
use std::process::ExitCode;

/// The version of the JSON shape: raised when a field changes meaning or goes away
/// (new fields may come without it).
pub const VERSION: u32 = 1;

/// The summary as the plan asks (`format_json`); the run's exit code, or 2 if
/// standard output could not take the JSON.
pub fn finish(plan: &RunPlan, seed: u64, summary: &Summary, code: ExitCode) -> ExitCode {
    if !plan.run.format_json {
        return code;
    }
    let mut line = json(plan, seed, summary).to_string();
    line.push('\n');
    crate::output::stdout_then(line.as_bytes(), code)
}

/// The JSON document: what the run was, then the summary's fields.
pub fn json(plan: &RunPlan, seed: u64, summary: &Summary) -> serde_json::Value {
    let mut doc = serde_json::json!({
        "version": VERSION,
        "application": plan.app,
        "seed": seed,
        "lockstep": plan.run.lockstep,
    });
    if let (Some(doc), Ok(serde_json::Value::Object(fields))) =
        (doc.as_object_mut(), serde_json::to_value(summary))
    {
        doc.extend(fields);
    }
    doc
}
