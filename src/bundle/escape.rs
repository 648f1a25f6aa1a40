//! The escapers askama applies to what a template of the bundle interpolates, one per
//! target language (`askama.toml`), and the filters that write a value in a language's
//! own syntax. All of them are the functions of `text.rs`: one place decides how model
//! text becomes generated text, whether an emitter or a template writes it.

use super::text;
use askama::filters::Escaper;
use std::fmt::{self, Write};

/// Rust: text that may end up in a `//` comment (printable ASCII, the rest escaped).
#[derive(Clone, Copy, Debug, Default)]
pub struct RustComment;

/// TOML: the inside of a basic string, also safe in a comment.
#[derive(Clone, Copy, Debug, Default)]
pub struct TomlText;

/// Shell scripts and systemd units: printable ASCII, the rest escaped (comments and
/// validated names; command words use the `shell` filter).
#[derive(Clone, Copy, Debug, Default)]
pub struct PlainText;

impl Escaper for RustComment {
    fn write_escaped_str<W: Write>(&self, mut dest: W, s: &str) -> fmt::Result {
        dest.write_str(&text::comment(s))
    }
}

impl Escaper for TomlText {
    fn write_escaped_str<W: Write>(&self, mut dest: W, s: &str) -> fmt::Result {
        dest.write_str(&text::toml_content(s))
    }
}

impl Escaper for PlainText {
    fn write_escaped_str<W: Write>(&self, mut dest: W, s: &str) -> fmt::Result {
        dest.write_str(&text::comment(s))
    }
}

/// Filters the templates call by name.
pub mod filters {
    use super::text;
    use askama::filters::Safe;
    use askama::{Result, Values};

    /// A Rust string literal of any text.
    #[askama::filter_fn]
    pub fn rust_str(s: impl ToString, _: &dyn Values) -> Result<Safe<String>> {
        Ok(Safe(text::rust_str(&s.to_string())))
    }

    /// A word for a POSIX shell, in single quotes.
    #[askama::filter_fn]
    pub fn shell(s: impl ToString, _: &dyn Values) -> Result<Safe<String>> {
        Ok(Safe(text::shell(&s.to_string())))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn escaped(e: impl Escaper, s: &str) -> String {
        let mut out = String::new();
        e.write_escaped_str(&mut out, s).unwrap();
        out
    }

    #[test]
    fn each_language_escapes_what_could_break_out() {
        assert_eq!(escaped(RustComment, "a\nfn x() {}"), "a\\u{a}fn x() {}");
        assert_eq!(escaped(TomlText, "a\"b\\\n"), r#"a\"b\\\u000A"#);
        assert_eq!(escaped(PlainText, "x\ny\u{202e}"), "x\\u{a}y\\u{202e}");
        // Names as the layout validated them pass unchanged.
        for name in ["crash_course-fragile_bot", "robot-pc.local", "/opt/robot"] {
            assert_eq!(escaped(PlainText, name), name);
            assert_eq!(escaped(TomlText, name), name);
        }
    }
}
