//! The human format: rustc-style rendering through miette, with the primary label on the
//! cause, secondary labels on related places (in other files, as related reports) and a
//! `help:` line.

use super::excerpt::{shorten_words, Excerpt, CONTEXT_LINES, TAB_WIDTH};
use super::ModelReport;
use ferroc_diagnostics::diagnostic::{Diagnostic, Severity};
use ferroc_diagnostics::source::{FileId, SourceMap};
use miette::{GraphicalReportHandler, GraphicalTheme, LabeledSpan, SourceCode};
use std::fmt;

#[derive(Debug)]
struct Rendered {
    message: String,
    /// `error[T106]`, as rustc heads its diagnostics.
    code: Option<String>,
    severity: miette::Severity,
    help: Option<String>,
    /// What miette sees of the file: the lines around the labels (see `excerpt`).
    source: Excerpt,
    labels: Vec<LabeledSpan>,
    related: Vec<Rendered>,
}

impl fmt::Display for Rendered {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Rendered {}

impl miette::Diagnostic for Rendered {
    fn code<'b>(&'b self) -> Option<Box<dyn fmt::Display + 'b>> {
        self.code
            .as_ref()
            .map(|c| Box::new(c) as Box<dyn fmt::Display + 'b>)
    }
    fn severity(&self) -> Option<miette::Severity> {
        Some(self.severity)
    }
    fn help<'b>(&'b self) -> Option<Box<dyn fmt::Display + 'b>> {
        self.help
            .as_ref()
            .map(|h| Box::new(h) as Box<dyn fmt::Display + 'b>)
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

/// The labels of one file, shown on an excerpt of it.
struct FileLabels<'a> {
    file: FileId,
    labels: Vec<(&'a ferroc_diagnostics::diagnostic::Label, bool)>,
}

impl FileLabels<'_> {
    fn excerpt(&self, sources: &SourceMap) -> (Excerpt, Vec<LabeledSpan>) {
        let file = sources.get(self.file);
        let ranges: Vec<(usize, usize)> = self
            .labels
            .iter()
            .map(|(l, _)| {
                let start = l.span.start as usize;
                // An empty span still marks one character (or the line break).
                (start, start + (l.span.end as usize - start).max(1))
            })
            .collect();
        let (excerpt, spans) = Excerpt::new(file, &ranges);
        let labeled = self
            .labels
            .iter()
            .zip(spans)
            .map(|((l, primary), span)| {
                let text = (!l.message.is_empty()).then(|| shorten_words(&l.message));
                if *primary {
                    LabeledSpan::new_primary_with_span(text, span)
                } else {
                    LabeledSpan::new_with_span(text, span)
                }
            })
            .collect();
        (excerpt, labeled)
    }
}

fn build(sources: &SourceMap, d: &Diagnostic) -> Rendered {
    let file = d.primary.span.file;
    // Labels grouped by file, the primary's file first; other files become related
    // reports, in the order they are first named.
    let mut files = vec![FileLabels {
        file,
        labels: vec![(&d.primary, true)],
    }];
    for s in &d.secondary {
        match files.iter_mut().find(|f| f.file == s.span.file) {
            Some(f) => f.labels.push((s, false)),
            None => files.push(FileLabels {
                file: s.span.file,
                labels: vec![(s, false)],
            }),
        }
    }
    let mut files = files.into_iter();
    let (source, labels) = files.next().expect("the primary's file").excerpt(sources);
    let related = files
        .map(|f| {
            let (source, labels) = f.excerpt(sources);
            Rendered {
                message: "related location".into(),
                code: None,
                severity: miette::Severity::Advice,
                help: None,
                source,
                labels,
                related: Vec::new(),
            }
        })
        .collect();
    Rendered {
        message: shorten_words(&d.message),
        code: Some(format!("{}[{}]", d.severity.as_str(), d.check.code)),
        severity: match d.severity {
            Severity::Error => miette::Severity::Error,
            Severity::Warning => miette::Severity::Warning,
            Severity::Note => miette::Severity::Advice,
        },
        help: d.help.as_deref().map(shorten_words),
        source,
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
        .tab_width(TAB_WIDTH)
        .with_context_lines(CONTEXT_LINES)
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
