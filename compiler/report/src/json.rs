//! `--format json`: the stable machine-readable report, documented in docs/json-format.md.

use super::ModelReport;
use ferroc_diagnostics::diagnostic::{Label, Severity, ThreadFlow};
use ferroc_diagnostics::source::{SourceMap, Span};
use serde_json::{json, Value};

/// Version of the JSON layout; bumped only on incompatible changes.
pub const FORMAT_VERSION: u32 = 1;

pub fn location(sources: &SourceMap, span: Span) -> Value {
    let file = sources.get(span.file);
    let (line, column) = file.line_col(span.start);
    let (end_line, end_column) = file.line_col(span.end);
    json!({
        "file": file.name,
        "line": line,
        "column": column,
        "end_line": end_line,
        "end_column": end_column,
        "byte_start": span.start,
        "byte_end": span.end,
    })
}

fn label(sources: &SourceMap, l: &Label) -> Value {
    json!({ "message": l.message, "location": location(sources, l.span) })
}

/// A deadlock witness, as SARIF's `codeFlows` carry it: one entry per blocked thread
/// container, its steps in order (where it took what it holds, then where it blocks).
/// Empty for every other finding, so a consumer needs no SARIF to walk a deadlock.
fn witness(sources: &SourceMap, flows: &[ThreadFlow]) -> Vec<Value> {
    flows
        .iter()
        .map(|t| {
            json!({
                "thread": t.thread,
                "message": t.message,
                "steps": t.locations.iter().map(|l| label(sources, l)).collect::<Vec<_>>(),
            })
        })
        .collect()
}

pub fn model(path: &str, report: &ModelReport<'_>) -> Value {
    let count = |s| {
        report
            .diagnostics
            .iter()
            .filter(|d| d.severity == s)
            .count()
    };
    let diagnostics: Vec<Value> = report
        .diagnostics
        .iter()
        .map(|d| {
            json!({
                "code": d.code(),
                "name": d.check.name,
                "severity": d.severity.as_str(),
                "message": d.message,
                "help": d.help,
                "primary": label(report.sources, &d.primary),
                "secondary": d.secondary.iter().map(|s| label(report.sources, s)).collect::<Vec<_>>(),
                "witness": witness(report.sources, &d.witness),
            })
        })
        .collect();
    json!({
        "model": path,
        "summary": {
            "errors": count(Severity::Error),
            "warnings": count(Severity::Warning),
            "notes": count(Severity::Note),
        },
        "diagnostics": diagnostics,
    })
}

pub fn document(models: Vec<Value>, tool_errors: Vec<Value>) -> Value {
    json!({
        "format_version": FORMAT_VERSION,
        "tool": { "name": "ferroc", "version": env!("CARGO_PKG_VERSION") },
        "models": models,
        "tool_errors": tool_errors,
    })
}
