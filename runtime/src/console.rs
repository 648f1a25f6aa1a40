//! Console output from modules that keeps `ferroc run`'s live status line intact.
//!
//! The status line is redrawn in place on a terminal; a module printing with
//! `println!` would land in the middle of it. [`line`] clears the status line first
//! (when one is shown), so the next redraw puts it back below the printed line.

use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};

static STATUS_LINE: AtomicBool = AtomicBool::new(false);

/// Tells [`line`] whether a status line is being drawn on the terminal.
pub fn set_status_line_active(active: bool) {
    STATUS_LINE.store(active, Ordering::Relaxed);
}

/// `text` with every control character but newline and tab written as an escape
/// (`\u{1b}`), and the bidirectional overrides too. Warnings and errors of a run carry
/// text from outside the program (model names, module panic messages, values from
/// peers); they must not drive the terminal. (The compiler escapes its diagnostics
/// the same way, `ferroc_compiler::diagnostic::escape_controls`; the runtime does not
/// depend on the compiler.)
pub fn escape(text: &str) -> std::borrow::Cow<'_, str> {
    let unsafe_char = |c: char| {
        (c.is_control() && c != '\n' && c != '\t')
            || matches!(c, '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}')
    };
    if !text.chars().any(unsafe_char) {
        return text.into();
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if unsafe_char(c) {
            out.extend(c.escape_unicode());
        } else {
            out.push(c);
        }
    }
    out.into()
}

/// Prints a warning or error of the run (already prefixed) on standard output like
/// [`line`], with control characters escaped.
pub fn report(text: &str) {
    line(&escape(text));
}

/// Prints one line to standard output (for what a user of a running application wants
/// to see: poses, collisions, at a human rate).
pub fn line(text: &str) {
    let mut out = std::io::stdout().lock();
    if STATUS_LINE.load(Ordering::Relaxed) {
        let _ = write!(std::io::stderr(), "\r\x1b[K");
    }
    let _ = writeln!(out, "{text}");
    let _ = out.flush();
}

#[cfg(test)]
mod tests {
    use super::escape;

    #[test]
    fn control_characters_are_escaped_and_lines_kept() {
        assert_eq!(escape("plain\tline\nnext"), "plain\tline\nnext");
        assert_eq!(
            escape("peer says \u{1b}[31mred\u{7}\u{9b}2J \u{202e}cba"),
            "peer says \\u{1b}[31mred\\u{7}\\u{9b}2J \\u{202e}cba"
        );
    }
}
