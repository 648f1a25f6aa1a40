//! Everything model content passes through on its way into generated files: names are
//! validated before they become identifiers, file names or Cargo names, and text is
//! escaped for the language it lands in (Rust literals and comments, TOML, XML, shell).

/// Rust's keywords, strict and reserved (2021 edition, plus `gen` of 2024).
const KEYWORDS: &[&str] = &[
    "abstract", "as", "async", "await", "become", "box", "break", "const", "continue", "crate",
    "do", "dyn", "else", "enum", "extern", "false", "final", "fn", "for", "gen", "if", "impl",
    "in", "let", "loop", "macro", "match", "mod", "move", "mut", "override", "priv", "pub", "ref",
    "return", "self", "Self", "static", "struct", "super", "trait", "true", "try", "type",
    "typeof", "unsafe", "unsized", "use", "virtual", "where", "while", "yield",
];

/// A model name: ASCII letters, digits and `_`, not starting with a digit (the model
/// language's rule, checked again here because generated code depends on it).
pub fn is_name(s: &str) -> bool {
    let mut chars = s.chars();
    matches!(chars.next(), Some(c) if c == '_' || c.is_ascii_alphabetic())
        && chars.all(|c| c == '_' || c.is_ascii_alphanumeric())
        && s.len() <= 128
}

/// A name usable as a Rust identifier: a model name that is not a keyword and not `_`.
pub fn is_rust_ident(s: &str) -> bool {
    is_name(s) && s != "_" && !KEYWORDS.contains(&s)
}

/// A Rust type path such as `crash_course::MainSimulation`: identifiers joined by `::`.
pub fn is_rust_path(s: &str) -> bool {
    let segments: Vec<&str> = s.split("::").collect();
    segments.len() >= 2 && segments.iter().all(|seg| is_rust_ident(seg))
}

/// A Rust type as the bundle writes it for a model type: paths and primitive names,
/// `Vec<…>` and `[…; N]` (nothing else can appear, so nothing else is accepted).
pub fn is_rust_type(s: &str) -> bool {
    let tokens = s
        .split(['<', '>', '[', ']', ';', ' '])
        .filter(|t| !t.is_empty());
    s.len() <= 256
        && tokens
            .into_iter()
            .all(|t| is_rust_path(t) || is_rust_ident(t) || t.bytes().all(|b| b.is_ascii_digit()))
}

/// A Cargo package name: ASCII letters, digits, `-` and `_`, starting with a letter.
pub fn is_crate_name(s: &str) -> bool {
    s.starts_with(|c: char| c.is_ascii_alphabetic())
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
        && s.len() <= 64
}

/// A semantic version as Cargo takes it (digits and dots, optional pre-release).
pub fn is_version(s: &str) -> bool {
    let core = s.split(['-', '+']).next().unwrap_or("");
    let parts: Vec<&str> = core.split('.').collect();
    parts.len() == 3
        && parts
            .iter()
            .all(|p| !p.is_empty() && p.chars().all(|c| c.is_ascii_digit()))
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '.' | '-' | '+'))
}

/// A Rust string literal (`"…"`) of any text: `Debug` escaping of `str` produces valid
/// Rust syntax for every input (quotes, backslashes, control and invisible characters).
pub fn rust_str(s: &str) -> String {
    format!("{s:?}")
}

/// Text safe inside a `//` comment: printable ASCII as is, everything else escaped
/// (a line break or a bidirectional override could otherwise end or disguise the
/// comment).
pub fn comment(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        if c == ' ' || c.is_ascii_graphic() {
            out.push(c);
        } else {
            out.push_str(&format!("\\u{{{:x}}}", c as u32));
        }
    }
    out
}

/// A TOML basic string (`"…"`), quotes included (scaffolds and runner manifests).
pub fn toml_str(s: &str) -> String {
    format!("\"{}\"", toml_content(s))
}

/// The inside of a TOML basic string: quotes, backslashes and control characters
/// escaped (so it is safe in a comment too).
pub fn toml_content(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if c.is_control() => out.push_str(&format!("\\u{:04X}", c as u32)),
            c => out.push(c),
        }
    }
    out
}

/// Text for an XML attribute value or element content: the compiler's one escaper
/// (`ferroc_compiler::syntax::escape::attr`), which is right in both places.
pub fn xml(s: &str) -> String {
    ferroc_compiler::syntax::escape::attr(s).into_owned()
}

/// Text safe inside an XML comment (`--` is not allowed there).
pub fn xml_comment(s: &str) -> String {
    comment(s).replace("--", "- -")
}

/// A word for a POSIX shell in single quotes.
pub fn shell(s: &str) -> String {
    format!("'{}'", s.replace('\'', r"'\''"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_that_cannot_break_out() {
        assert!(is_rust_ident("main_simulation"));
        for bad in [
            "", "1x", "a-b", "a b", "a\"", "fn", "self", "_", "a::b", "é",
        ] {
            assert!(!is_rust_ident(bad), "{bad:?}");
        }
        assert!(is_rust_path("crash_course::MainSimulation"));
        for bad in [
            "X",
            "a::",
            "::a",
            "a::b; std::process::exit(1)",
            "a::b<T>",
            "a::fn",
        ] {
            assert!(!is_rust_path(bad), "{bad:?}");
        }
        for good in [
            "f64",
            "Vec<String>",
            "[f64; 3]",
            "Vec<rescue_components::Pose2D>",
        ] {
            assert!(is_rust_type(good), "{good:?}");
        }
        for bad in [
            "a::b(1)",
            "Vec<a\"b>",
            "x { }",
            "a::b!",
            "u8, exit()",
            "&'static str",
        ] {
            assert!(!is_rust_type(bad), "{bad:?}");
        }
        assert!(is_version("0.1.0") && is_version("1.2.3-beta.1"));
        assert!(!is_version("1") && !is_version("1.0.0\"x"));
    }

    #[test]
    fn escaping() {
        assert_eq!(rust_str("a\"b\\c\nd"), r#""a\"b\\c\nd""#);
        assert_eq!(comment("a\nfn x() {}"), "a\\u{a}fn x() {}");
        assert_eq!(comment("x\u{202e}y"), "x\\u{202e}y");
        assert_eq!(toml_content("a\"b\\\n"), r#"a\"b\\\u000A"#);
        assert_eq!(xml("<a & \"b\">"), "&lt;a &amp; &quot;b&quot;&gt;");
        assert_eq!(xml_comment("a--b"), "a- -b");
        assert_eq!(shell("it's"), r"'it'\''s'");
    }
}
