//! The error of a definition file: where (file:line:col), what, and what to do.
use std::fmt;

/// A problem in an interface definition, at a place in a file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DefinitionError {
    /// The file as the user named it (a path, or `<shipped>/pkg/msg/Name.msg`).
    pub file: String,
    /// 1-based line.
    pub line: usize,
    /// 1-based column (in characters).
    pub col: usize,
    /// What is wrong, in plain words.
    pub message: String,
    /// What the user can change.
    pub help: String,
}

impl DefinitionError {
    pub(crate) fn new(file: &str, line: usize, col: usize, message: String, help: &str) -> Self {
        DefinitionError {
            file: file.to_string(),
            line,
            col,
            message,
            help: help.to_string(),
        }
    }
}

impl fmt::Display for DefinitionError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}:{}:{}: {}\n  help: {}",
            self.file, self.line, self.col, self.message, self.help
        )
    }
}

impl std::error::Error for DefinitionError {}
