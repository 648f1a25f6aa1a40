//! `--format junit`: one test suite per model, one test case per check. A check fails on a
//! model when it reports an error there; warnings and notes are listed as output.

use super::ModelReport;
use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_syntax::escape;

/// `tool_errors` (models ferroc could not check, exit code 2) each become a failing
/// test case of their own suite, so that a CI reading only the JUnit file sees the
/// failure (without them it saw `tests="0"`, which passes).
pub fn document(
    checks: &[&CheckInfo],
    models: &[(String, ModelReport<'_>)],
    tool_errors: &[String],
) -> String {
    let mut out = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let total = models.len() * checks.len() + tool_errors.len();
    let failures: usize = models
        .iter()
        .map(|(_, r)| failing_checks(checks, r))
        .sum::<usize>()
        + tool_errors.len();
    out.push_str(&format!(
        "<testsuites name=\"ferroc check\" tests=\"{total}\" failures=\"{failures}\">\n"
    ));
    if !tool_errors.is_empty() {
        tool_error_suite(tool_errors, &mut out);
    }
    for (path, report) in models {
        model_suite(checks, path, report, &mut out);
    }
    out.push_str("</testsuites>\n");
    out
}

/// How many of `checks` report an error in `report`.
fn failing_checks(checks: &[&CheckInfo], report: &ModelReport<'_>) -> usize {
    checks
        .iter()
        .filter(|c| {
            report
                .diagnostics
                .iter()
                .any(|d| d.code() == c.code && d.severity == Severity::Error)
        })
        .count()
}

/// The suite `ferroc` of the models that could not be checked, one failing test case
/// each.
fn tool_error_suite(tool_errors: &[String], out: &mut String) {
    let n = tool_errors.len();
    out.push_str(&format!(
        "  <testsuite name=\"ferroc\" tests=\"{n}\" failures=\"{n}\">\n"
    ));
    for e in tool_errors {
        out.push_str(&format!(
            "    <testcase classname=\"ferroc\" name=\"check could run\">\n      \
             <failure message=\"ferroc could not check\" type=\"tool-error\">{}</failure>\n    \
             </testcase>\n",
            escape::text(e)
        ));
    }
    out.push_str("  </testsuite>\n");
}

/// The suite of one model: a test case per check.
fn model_suite(checks: &[&CheckInfo], path: &str, report: &ModelReport<'_>, out: &mut String) {
    let fails = failing_checks(checks, report);
    out.push_str(&format!(
        "  <testsuite name=\"{}\" tests=\"{}\" failures=\"{fails}\">\n",
        escape::attr(path),
        checks.len()
    ));
    for check in checks {
        test_case(check, path, report, out);
    }
    out.push_str("  </testsuite>\n");
}

/// The test case of one check on one model: failing with its errors, or passing with
/// its other findings as output.
fn test_case(check: &CheckInfo, path: &str, report: &ModelReport<'_>, out: &mut String) {
    let found: Vec<_> = report
        .diagnostics
        .iter()
        .filter(|d| d.code() == check.code)
        .collect();
    let lines: Vec<String> = found
        .iter()
        .map(|d| {
            let (f, l, c) = report.sources.location(d.primary.span);
            format!(
                "{f}:{l}:{c}: {}[{}]: {}",
                d.severity.as_str(),
                d.code(),
                d.message
            )
        })
        .collect();
    let name = format!("{} {}", check.code, check.name);
    out.push_str(&format!(
        "    <testcase classname=\"{}\" name=\"{}\"",
        escape::attr(path),
        escape::attr(&name)
    ));
    if found.is_empty() {
        out.push_str("/>\n");
        return;
    }
    out.push_str(">\n");
    let errors = found
        .iter()
        .filter(|d| d.severity == Severity::Error)
        .count();
    if errors > 0 {
        out.push_str(&format!(
            "      <failure message=\"{} error(s)\" type=\"{}\">{}</failure>\n",
            errors,
            check.code,
            escape::text(&lines.join("\n"))
        ));
    } else {
        out.push_str(&format!(
            "      <system-out>{}</system-out>\n",
            escape::text(&lines.join("\n"))
        ));
    }
    out.push_str("    </testcase>\n");
}
