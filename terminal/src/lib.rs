//! Text that reaches a terminal from outside the program: names and values from a
//! model (`name="&#27;[31m"`), messages of panicking modules, values from peers. Such
//! text must not drive the terminal (colour, cursor moves, a cleared screen) or
//! reorder what it shows (bidirectional overrides), so [`escape_controls`] writes those
//! characters as visible escapes. The compiler's diagnostics and the runtime's console
//! both print through it; it depends on nothing, so the runtime can use it without the
//! compiler.
//!
//! [`engine_error`] (`engine.rs`) does the same for the errors of the libraries ferroc
//! runs on: a dependency's source paths and `Debug` dumps never reach a user.

#![forbid(unsafe_code)]

mod engine;

pub use engine::engine_error;
use std::borrow::Cow;

/// Whether `c` is written as an escape: a control character other than newline and
/// tab, or a bidirectional embedding, override or isolate (U+202A–U+202E,
/// U+2066–U+2069).
pub fn is_unsafe(c: char) -> bool {
    (c.is_control() && c != '\n' && c != '\t')
        || matches!(c, '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}')
}

/// `text` with every unsafe character ([`is_unsafe`]) written as a Rust-style escape
/// (`\u{1b}`); borrowed when there is none.
pub fn escape_controls(text: &str) -> Cow<'_, str> {
    if !text.chars().any(is_unsafe) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if is_unsafe(c) {
            out.extend(c.escape_unicode());
        } else {
            out.push(c);
        }
    }
    Cow::Owned(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn controls_and_bidi_overrides_become_visible_escapes() {
        assert_eq!(
            escape_controls("\u{1b}[31mred\u{7}\r\u{202e}evil\u{2066}"),
            "\\u{1b}[31mred\\u{7}\\u{d}\\u{202e}evil\\u{2066}"
        );
    }

    #[test]
    fn newlines_tabs_and_ordinary_text_stay_as_they_are() {
        let text = "two\nlines\tand ünïcode ✓ → robot/main";
        assert!(matches!(escape_controls(text), Cow::Borrowed(t) if t == text));
    }
}
