//! `--format sarif`: SARIF 2.1.0 as GitHub code scanning reads it.

use super::ModelReport;
use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::source::{SourceMap, Span};
use serde_json::{json, Value};

fn uri(name: &str) -> String {
    let mut out = String::new();
    for c in name.replace('\\', "/").chars() {
        match c {
            'A'..='Z' | 'a'..='z' | '0'..='9' | '-' | '_' | '.' | '~' | '/' | ':' => out.push(c),
            other => {
                let mut buf = [0u8; 4];
                for b in other.encode_utf8(&mut buf).bytes() {
                    out.push_str(&format!("%{b:02X}"));
                }
            }
        }
    }
    out
}

fn physical(sources: &SourceMap, span: Span) -> Value {
    let file = sources.get(span.file);
    let (line, col) = file.line_col(span.start);
    let (end_line, end_col) = file.line_col(span.end.max(span.start + 1));
    json!({
        "artifactLocation": { "uri": uri(&file.name) },
        "region": { "startLine": line, "startColumn": col, "endLine": end_line, "endColumn": end_col }
    })
}

fn level(s: Severity) -> &'static str {
    match s {
        Severity::Error => "error",
        Severity::Warning => "warning",
        Severity::Note => "note",
    }
}

/// A deadlock witness as one `codeFlow` with one `threadFlow` per blocked thread
/// container (`reference/deadlocks.md` §2.8).
fn code_flows(
    sources: &SourceMap,
    witness: &[ferroc_diagnostics::diagnostic::ThreadFlow],
) -> Value {
    let thread_flows: Vec<Value> = witness
        .iter()
        .map(|t| {
            let locations: Vec<Value> = t
                .locations
                .iter()
                .map(|l| {
                    json!({
                        "location": {
                            "physicalLocation": physical(sources, l.span),
                            "message": { "text": l.message },
                        },
                    })
                })
                .collect();
            json!({
                "id": t.thread,
                "message": { "text": t.message },
                "locations": locations,
            })
        })
        .collect();
    json!([{
        "message": { "text": format!("deadlock witness: {} blocked thread container(s)", witness.len()) },
        "threadFlows": thread_flows,
    }])
}

/// One SARIF log with one run covering every checked model; `checks` are the rules
/// (`ferroc_compiler::checks::REGISTRY`).
pub fn document(checks: &[&CheckInfo], reports: &[ModelReport<'_>]) -> Value {
    let rules: Vec<Value> = checks
        .iter()
        .map(|c| {
            json!({
                "id": c.code,
                "name": c.name,
                "shortDescription": { "text": c.summary },
                "fullDescription": { "text": c.explanation },
                "help": { "text": c.explanation },
                "defaultConfiguration": { "level": level(c.severity) },
            })
        })
        .collect();
    let mut results = Vec::new();
    for report in reports {
        for d in report.diagnostics {
            let rule_index = checks.iter().position(|c| c.code == d.code()).unwrap_or(0);
            let mut text = d.message.clone();
            if let Some(h) = &d.help {
                text.push_str("\nhelp: ");
                text.push_str(h);
            }
            let related: Vec<Value> = d
                .secondary
                .iter()
                .enumerate()
                .map(|(i, s)| {
                    json!({
                        "id": i,
                        "physicalLocation": physical(report.sources, s.span),
                        "message": { "text": if s.message.is_empty() { "related location" } else { &s.message } },
                    })
                })
                .collect();
            let mut result = json!({
                "ruleId": d.code(),
                "ruleIndex": rule_index,
                "level": level(d.severity),
                "message": { "text": text },
                "locations": [{ "physicalLocation": physical(report.sources, d.primary.span) }],
            });
            if !related.is_empty() {
                result["relatedLocations"] = Value::Array(related);
            }
            if !d.witness.is_empty() {
                result["codeFlows"] = code_flows(report.sources, &d.witness);
            }
            results.push(result);
        }
    }
    json!({
        "$schema": "https://json.schemastore.org/sarif-2.1.0.json",
        "version": "2.1.0",
        "runs": [{
            "tool": { "driver": {
                "name": "ferroc",
                "version": env!("CARGO_PKG_VERSION"),
                "informationUri": "https://github.com/ferroc/ferroc",
                "rules": rules,
            }},
            "columnKind": "unicodeCodePoints",
            "results": results,
        }]
    })
}

/// Adds the invocation to a SARIF document: whether ferroc could check everything, and
/// why not (a model file it could not read, exit code 2) as tool execution
/// notifications. Without it a run that failed looked like a clean one: no result.
pub fn add_invocation(doc: &mut Value, tool_errors: &[String]) {
    let notifications: Vec<Value> = tool_errors
        .iter()
        .map(|e| json!({ "level": "error", "message": { "text": e } }))
        .collect();
    let mut invocation = json!({ "executionSuccessful": tool_errors.is_empty() });
    if !notifications.is_empty() {
        invocation["toolExecutionNotifications"] = Value::Array(notifications);
    }
    if let Some(run) = doc["runs"].get_mut(0) {
        run["invocations"] = json!([invocation]);
    }
}
