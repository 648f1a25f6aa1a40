//! The human format: rustc-style rendering through miette, with the primary label on the
//! cause, secondary labels on related places (in other files, as related reports) and a
//! `help:` line.

use super::ModelReport;
use crate::diagnostic::{Diagnostic, Severity};
use crate::source::{FileId, SourceMap};
use miette::{
    GraphicalReportHandler, GraphicalTheme, LabeledSpan, MietteError, MietteSpanContents,
    SourceCode, SourceSpan, SpanContents,
};
use std::fmt;

/// A file's text with its name, as miette wants it.
#[derive(Debug)]
struct NamedText<'a> {
    name: &'a str,
    text: &'a str,
}

impl SourceCode for NamedText<'_> {
    fn read_span<'b>(
        &'b self,
        span: &SourceSpan,
        before: usize,
        after: usize,
    ) -> Result<Box<dyn SpanContents<'b> + 'b>, MietteError> {
        let inner = self.text.read_span(span, before, after)?;
        Ok(Box::new(MietteSpanContents::new_named(
            self.name.to_string(),
            inner.data(),
            *inner.span(),
            inner.line(),
            inner.column(),
            inner.line_count(),
        )))
    }
}

#[derive(Debug)]
struct Rendered<'a> {
    message: String,
    /// `error[T106]`, as rustc heads its diagnostics.
    code: Option<String>,
    severity: miette::Severity,
    help: Option<&'a str>,
    source: NamedText<'a>,
    labels: Vec<LabeledSpan>,
    related: Vec<Rendered<'a>>,
}

impl fmt::Display for Rendered<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Rendered<'_> {}

impl miette::Diagnostic for Rendered<'_> {
    fn code<'b>(&'b self) -> Option<Box<dyn fmt::Display + 'b>> {
        self.code
            .as_ref()
            .map(|c| Box::new(c) as Box<dyn fmt::Display + 'b>)
    }
    fn severity(&self) -> Option<miette::Severity> {
        Some(self.severity)
    }
    fn help<'b>(&'b self) -> Option<Box<dyn fmt::Display + 'b>> {
        self.help.map(|h| Box::new(h) as Box<dyn fmt::Display>)
    }
    fn source_code(&self) -> Option<&dyn SourceCode> {
        Some(&self.source)
    }
    fn labels(&self) -> Option<Box<dyn Iterator<Item = LabeledSpan> + '_>> {
        Some(Box::new(self.labels.iter().cloned()))
    }
    fn related<'b>(&'b self) -> Option<Box<dyn Iterator<Item = &'b dyn miette::Diagnostic> + 'b>> {
        if self.related.is_empty() {
            return None;
        }
        Some(Box::new(
            self.related.iter().map(|r| r as &dyn miette::Diagnostic),
        ))
    }
}

fn labeled(sources: &SourceMap, label: &crate::diagnostic::Label, primary: bool) -> LabeledSpan {
    let len = (label.span.end - label.span.start).max(1) as usize;
    let text = (!label.message.is_empty()).then(|| label.message.clone());
    let span = SourceSpan::new(
        (label.span.start as usize).into(),
        len.min(
            sources
                .get(label.span.file)
                .text
                .len()
                .saturating_sub(label.span.start as usize),
        ),
    );
    if primary {
        LabeledSpan::new_primary_with_span(text, span)
    } else {
        LabeledSpan::new_with_span(text, span)
    }
}

fn build<'a>(sources: &'a SourceMap, d: &'a Diagnostic) -> Rendered<'a> {
    let file = d.primary.span.file;
    let named = |f: FileId| {
        let src = sources.get(f);
        NamedText {
            name: &src.name,
            text: &src.text,
        }
    };
    let mut labels = vec![labeled(sources, &d.primary, true)];
    let mut related: Vec<Rendered<'a>> = Vec::new();
    for s in &d.secondary {
        if s.span.file == file {
            labels.push(labeled(sources, s, false));
        } else if let Some(r) = related
            .iter_mut()
            .find(|r| std::ptr::eq(r.source.text, sources.get(s.span.file).text.as_str()))
        {
            r.labels.push(labeled(sources, s, false));
        } else {
            related.push(Rendered {
                message: "related location".into(),
                code: None,
                severity: miette::Severity::Advice,
                help: None,
                source: named(s.span.file),
                labels: vec![labeled(sources, s, false)],
                related: Vec::new(),
            });
        }
    }
    Rendered {
        message: d.message.clone(),
        code: Some(format!("{}[{}]", d.severity.as_str(), d.check.code)),
        severity: match d.severity {
            Severity::Error => miette::Severity::Error,
            Severity::Warning => miette::Severity::Warning,
            Severity::Note => miette::Severity::Advice,
        },
        help: d.help.as_deref(),
        source: named(file),
        labels,
        related,
    }
}

/// Renders every finding; `color` for terminals.
pub fn render(report: &ModelReport<'_>, color: bool, out: &mut String) {
    let theme = if color {
        GraphicalTheme::unicode()
    } else {
        GraphicalTheme::unicode_nocolor()
    };
    let handler = GraphicalReportHandler::new_themed(theme)
        .with_width(100)
        .with_links(false);
    for d in report.diagnostics {
        let rendered = build(report.sources, d);
        if handler.render_report(out, &rendered).is_err() {
            let (f, l, c) = report.sources.location(d.primary.span);
            out.push_str(&format!(
                "{}[{}]: {} at {f}:{l}:{c}\n",
                d.severity.as_str(),
                d.code(),
                d.message
            ));
        }
        out.push('\n');
    }
}
