//! The compiler's findings as LSP diagnostics: the same code, severity, message and
//! range `ferroc check` reports; secondary labels and the steps of a deadlock witness
//! as related information; `help:` appended to the message as the terminal shows it.

use crate::position::{Encoding, LineIndex};
use ferroc_compiler::diagnostic::{Diagnostic, Severity};
use ferroc_compiler::source::{SourceMap, Span};
use lsp_types::{
    DiagnosticRelatedInformation, DiagnosticSeverity, Location, NumberOrString, Range, Url,
};
use std::collections::HashMap;
use std::path::PathBuf;

/// Line indexes of a check run's files, made once per file when first needed.
pub struct Spans<'a> {
    pub sources: &'a SourceMap,
    pub enc: Encoding,
    lines: HashMap<u32, LineIndex>,
}

impl<'a> Spans<'a> {
    pub fn new(sources: &'a SourceMap, enc: Encoding) -> Self {
        Spans {
            sources,
            enc,
            lines: HashMap::new(),
        }
    }

    pub fn range(&mut self, span: Span) -> Range {
        let file = self.sources.get(span.file);
        let index = (self.lines)
            .entry(span.file.0)
            .or_insert_with(|| LineIndex::new(&file.text));
        index.range(&file.text, span.start as usize, span.end as usize, self.enc)
    }

    /// The file a span is in, when it is a file on disk (the built-in standard
    /// library's manifest is not).
    pub fn path(&self, span: Span) -> Option<PathBuf> {
        let path = &self.sources.get(span.file).path;
        path.is_absolute().then(|| path.clone())
    }

    pub fn location(&mut self, span: Span) -> Option<Location> {
        let uri = Url::from_file_path(self.path(span)?).ok()?;
        Some(Location::new(uri, self.range(span)))
    }
}

pub fn severity(s: Severity) -> DiagnosticSeverity {
    match s {
        Severity::Error => DiagnosticSeverity::ERROR,
        Severity::Warning => DiagnosticSeverity::WARNING,
        Severity::Note => DiagnosticSeverity::INFORMATION,
    }
}

/// One finding as the editor shows it.
pub fn diagnostic(d: &Diagnostic, spans: &mut Spans<'_>) -> lsp_types::Diagnostic {
    let mut related = Vec::new();
    for label in &d.secondary {
        if let Some(location) = spans.location(label.span) {
            related.push(DiagnosticRelatedInformation {
                location,
                message: label.message.clone(),
            });
        }
    }
    for flow in &d.witness {
        for step in &flow.locations {
            if let Some(location) = spans.location(step.span) {
                related.push(DiagnosticRelatedInformation {
                    location,
                    message: format!("{}: {}", flow.thread, step.message),
                });
            }
        }
    }
    let mut message = d.message.clone();
    if !d.primary.message.is_empty() {
        message.push_str(&format!("\n{}", d.primary.message));
    }
    if let Some(help) = &d.help {
        message.push_str(&format!("\nhelp: {help}"));
    }
    message.push_str(&format!("\n(ferroc explain {})", d.code()));
    lsp_types::Diagnostic {
        range: spans.range(d.primary.span),
        severity: Some(severity(d.severity)),
        code: Some(NumberOrString::String(d.code().to_string())),
        code_description: None,
        source: Some("ferroc".into()),
        message,
        related_information: (!related.is_empty()).then_some(related),
        tags: None,
        data: None,
    }
}
