//! Report formats: human (miette), short, json, sarif, junit.

#![forbid(unsafe_code)]

mod excerpt;
pub mod human;
pub mod json;
pub mod junit;
pub mod sarif;

use ferroc_diagnostics::diagnostic::Diagnostic;
use ferroc_diagnostics::source::SourceMap;

/// One checked model, as the reports see it.
pub struct ModelReport<'a> {
    pub sources: &'a SourceMap,
    pub diagnostics: &'a [Diagnostic],
}

/// `FILE:LINE:COL: SEVERITY[CODE]: message` — one finding per line.
pub fn short(report: &ModelReport<'_>, out: &mut String) {
    for d in report.diagnostics {
        let (file, line, col) = report.sources.location(d.primary.span);
        out.push_str(&format!(
            "{file}:{line}:{col}: {}[{}]: {}\n",
            d.severity.as_str(),
            d.code(),
            d.message
        ));
    }
}
