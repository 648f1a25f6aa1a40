//! Findings: what a check reports, independent of how it is rendered.

use crate::check::CheckInfo;
use crate::source::Span;
use serde::Serialize;

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    Note,
    Warning,
    Error,
}

impl Severity {
    pub fn as_str(self) -> &'static str {
        match self {
            Severity::Note => "note",
            Severity::Warning => "warning",
            Severity::Error => "error",
        }
    }
}

/// A source location with a short message ("expected `f64` here").
#[derive(Clone, Debug)]
pub struct Label {
    pub span: Span,
    pub message: String,
}

/// One finding of one check.
#[derive(Clone, Debug)]
pub struct Diagnostic {
    pub check: &'static CheckInfo,
    pub severity: Severity,
    pub message: String,
    /// The cause. Always present: every finding points somewhere.
    pub primary: Label,
    /// Related places, possibly in other files (the other end of a connection, …).
    pub secondary: Vec<Label>,
    /// The suggested fix.
    pub help: Option<String>,
    /// A deadlock witness: one flow per blocked thread container (SARIF `codeFlows`).
    pub witness: Vec<ThreadFlow>,
}

/// What one thread container does on a deadlock cycle, in order: where it took what it
/// holds, then where it blocks (the last location's message says what it waits for).
#[derive(Clone, Debug)]
pub struct ThreadFlow {
    /// The thread container's path (`robot/T1`).
    pub thread: String,
    /// `thread container `robot/T1` (part `robot`, host `pc1`)`.
    pub message: String,
    pub locations: Vec<Label>,
}

/// `text` with every control character but newline and tab written as an escape
/// (`\u{1b}`), and the bidirectional overrides too: names and values from a model
/// (`name="&#27;[31m"`) reach the terminal in messages, and must not drive it or
/// reorder what it shows. Every message, label and help of a [`Diagnostic`] passes
/// through here when it is built.
pub fn escape_controls(text: impl Into<String>) -> String {
    let text = text.into();
    let unsafe_char = |c: char| {
        (c.is_control() && c != '\n' && c != '\t')
            || matches!(c, '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}')
    };
    if !text.chars().any(unsafe_char) {
        return text;
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if unsafe_char(c) {
            out.extend(c.escape_unicode());
        } else {
            out.push(c);
        }
    }
    out
}

impl Diagnostic {
    pub fn new(check: &'static CheckInfo, span: Span, message: impl Into<String>) -> Self {
        Diagnostic {
            check,
            severity: check.severity,
            message: escape_controls(message),
            primary: Label {
                span,
                message: String::new(),
            },
            secondary: Vec::new(),
            help: None,
            witness: Vec::new(),
        }
    }

    /// Short text under the primary caret.
    pub fn label(mut self, message: impl Into<String>) -> Self {
        self.primary.message = escape_controls(message);
        self
    }

    pub fn secondary(mut self, span: Span, message: impl Into<String>) -> Self {
        self.secondary.push(Label {
            span,
            message: escape_controls(message),
        });
        self
    }

    pub fn help(mut self, help: impl Into<String>) -> Self {
        self.help = Some(escape_controls(help));
        self
    }

    pub fn witness(mut self, mut witness: Vec<ThreadFlow>) -> Self {
        for flow in &mut witness {
            flow.message = escape_controls(std::mem::take(&mut flow.message));
            for l in &mut flow.locations {
                l.message = escape_controls(std::mem::take(&mut l.message));
            }
        }
        self.witness = witness;
        self
    }

    pub fn severity(mut self, severity: Severity) -> Self {
        self.severity = severity;
        self
    }

    pub fn code(&self) -> &'static str {
        self.check.code
    }
}

/// The findings of a run, in the order they were found.
#[derive(Default, Debug)]
pub struct Diagnostics {
    pub items: Vec<Diagnostic>,
}

impl Diagnostics {
    pub fn push(&mut self, d: Diagnostic) {
        self.items.push(d);
    }

    pub fn has_errors(&self) -> bool {
        self.items.iter().any(|d| d.severity == Severity::Error)
    }

    pub fn count(&self, severity: Severity) -> usize {
        self.items.iter().filter(|d| d.severity == severity).count()
    }
}

/// "did you mean `x`?" — the closest candidate within a small edit distance.
pub fn did_you_mean<'a>(
    word: &str,
    candidates: impl IntoIterator<Item = &'a str>,
) -> Option<&'a str> {
    let limit = (word.chars().count() / 3).max(1) + 1;
    candidates
        .into_iter()
        .map(|c| {
            (
                edit_distance(&word.to_ascii_lowercase(), &c.to_ascii_lowercase()),
                c,
            )
        })
        .filter(|(d, _)| *d <= limit)
        .min_by_key(|(d, c)| (*d, *c))
        .map(|(_, c)| c)
}

fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = if ca == *cb {
                prev
            } else {
                1 + prev.min(row[j]).min(row[j + 1])
            };
            prev = cur;
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn suggests_close_names_only() {
        assert_eq!(
            did_you_mean("conect", ["connect", "module"]),
            Some("connect")
        );
        assert_eq!(did_you_mean("Modul", ["connect", "module"]), Some("module"));
        assert_eq!(did_you_mean("zzzzzz", ["connect", "module"]), None);
    }
}
