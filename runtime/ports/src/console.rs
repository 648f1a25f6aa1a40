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
/// peers); they must not drive the terminal. The compiler's diagnostics escape with
/// the same function (`ferroc_terminal`, which depends on nothing).
pub fn escape(text: &str) -> std::borrow::Cow<'_, str> {
    ferroc_terminal::escape_controls(text)
}

/// Prints a warning or error of the run (already prefixed) on standard output like
/// [`line()`], with control characters escaped, and throttled: the same text again is
/// printed only at its 10th, 100th, 1000th … occurrence, with the count (a peer
/// sending 20,000 bad frames gives five lines, not 20,000).
pub fn report(text: &str) {
    let shown = (REPEATS.lock().unwrap_or_else(|p| p.into_inner())).note(text);
    if let Some(text) = shown {
        line(&escape(&text));
    }
}

/// [`report`] for a text that varies from one occurrence to the next (a foreign peer's
/// bytes in it, a length, a hash): counted by `kind` instead (e.g. the topic and what
/// was wrong), so a flood of samples each wrong in its own way still prints only the
/// 1st, 10th, 100th … of each kind, that occurrence's text with the count.
pub fn report_as(kind: &str, text: &str) {
    let shown = (REPEATS.lock().unwrap_or_else(|p| p.into_inner())).note_as(kind, text);
    if let Some(text) = shown {
        line(&escape(&text));
    }
}

static REPEATS: std::sync::Mutex<Throttle> = std::sync::Mutex::new(Throttle::new());

/// Counts repeated texts and says which occurrences to show.
pub(crate) struct Throttle {
    seen: Option<std::collections::HashMap<String, u64>>,
}

/// How many distinct texts are counted; beyond that, new texts are shown every time
/// (a bound on memory, far above what a run prints).
const DISTINCT: usize = 4096;

impl Throttle {
    pub(crate) const fn new() -> Self {
        Throttle { seen: None }
    }

    /// The line to print for this occurrence of `text`, if any: the first as it is,
    /// the 10th, 100th, … with how often it came.
    pub(crate) fn note(&mut self, text: &str) -> Option<String> {
        self.note_as(text, text)
    }

    /// [`Self::note`] counting occurrences of `kind`, showing `text`.
    pub(crate) fn note_as(&mut self, kind: &str, text: &str) -> Option<String> {
        let seen = self.seen.get_or_insert_with(Default::default);
        let count = if let Some(n) = seen.get_mut(kind) {
            *n += 1;
            *n
        } else if seen.len() < DISTINCT {
            seen.insert(kind.to_owned(), 1);
            1
        } else {
            return Some(text.to_owned());
        };
        match count {
            1 => Some(text.to_owned()),
            n if is_power_of_ten(n) && kind == text => {
                Some(format!("{text} (repeated: {n} times so far)"))
            }
            n if is_power_of_ten(n) => Some(format!("{text} ({n} of this kind so far)")),
            _ => None,
        }
    }
}

fn is_power_of_ten(mut n: u64) -> bool {
    while n >= 10 && n % 10 == 0 {
        n /= 10;
    }
    n == 1
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

/// Prints one line to standard error (for what the operator should know about the run
/// itself: parts waited for, gone or back), keeping the status line intact. Standard
/// output stays the application's own.
pub fn note(text: &str) {
    let mut err = std::io::stderr().lock();
    if STATUS_LINE.load(Ordering::Relaxed) {
        let _ = write!(err, "\r\x1b[K");
    }
    let _ = writeln!(err, "{}", escape(text));
}

/// [`note()`], throttled as [`report()`] is: the same text again is written only at its
/// 10th, 100th, 1000th … occurrence, with the count. For what a client can make us say
/// as often as it likes (a wrong token, 2,000 tries in a fraction of a second).
pub fn note_repeated(text: &str) {
    let shown = (REPEATS.lock().unwrap_or_else(|p| p.into_inner())).note(text);
    if let Some(text) = shown {
        note(&text);
    }
}

/// Writes one line to standard error, dropping it when standard error cannot be
/// written (a pipe whose reader is gone, a full disk). std's `eprintln!` panics there,
/// turning a lost message into a crash (exit 101); the crates of ferroc shadow
/// `eprintln!` with a macro that calls this.
pub fn stderr_line(args: std::fmt::Arguments<'_>) {
    let _ = writeln!(std::io::stderr().lock(), "{args}");
}

#[cfg(test)]
mod tests {
    use super::{escape, Throttle};

    #[test]
    fn a_repeated_warning_is_shown_at_powers_of_ten() {
        let mut t = Throttle::new();
        let shown: Vec<String> = (0..20_000)
            .filter_map(|_| t.note("warning: bad frame"))
            .collect();
        assert_eq!(
            shown,
            [
                "warning: bad frame",
                "warning: bad frame (repeated: 10 times so far)",
                "warning: bad frame (repeated: 100 times so far)",
                "warning: bad frame (repeated: 1000 times so far)",
                "warning: bad frame (repeated: 10000 times so far)",
            ]
        );
        // Another text is counted on its own.
        assert_eq!(t.note("warning: other").as_deref(), Some("warning: other"));
    }

    #[test]
    fn varying_texts_of_one_kind_are_counted_together() {
        let mut t = Throttle::new();
        let shown: Vec<String> = (0..1000)
            .filter_map(|n| t.note_as("topic /a: header", &format!("bad header {n}")))
            .collect();
        assert_eq!(
            shown,
            [
                "bad header 0",
                "bad header 9 (10 of this kind so far)",
                "bad header 99 (100 of this kind so far)",
                "bad header 999 (1000 of this kind so far)",
            ]
        );
        // Another kind is counted on its own, the same text of another kind too.
        assert_eq!(
            t.note_as("topic /b: header", "bad header 0").as_deref(),
            Some("bad header 0")
        );
    }

    #[test]
    fn control_characters_are_escaped_and_lines_kept() {
        assert_eq!(escape("plain\tline\nnext"), "plain\tline\nnext");
        assert_eq!(
            escape("peer says \u{1b}[31mred\u{7}\u{9b}2J \u{202e}cba"),
            "peer says \\u{1b}[31mred\\u{7}\\u{9b}2J \\u{202e}cba"
        );
    }
}
