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
    let _ = writeln!(err, "{text}");
}
