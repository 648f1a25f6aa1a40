//! Text written into XML: the one escaper every writer of ours uses (bundles' resolved
//! models and manifests, `ferroc types export`, edited models, JUnit reports, FINROC
//! files and imports).
//!
//! Two places, two rules, one implementation:
//!
//! * [`attr`]: a value inside double quotes. `&`, `<`, `>` and `"` become entities, and
//!   tab, newline and carriage return become character references: a reader normalises
//!   them to spaces otherwise (XML 1.0 §3.3.3), so a two-line `doc` would come back as
//!   one line.
//! * [`text`]: element content. `&` and `<` become entities, `>` only where it would
//!   close `]]>` (so `in/0 -> out` stays readable in a model), carriage return a
//!   character reference (a reader turns it into a newline otherwise).
//! * [`content`]: element content as libxml2 (FINROC's writer) escapes it: as [`text`],
//!   and every `>` an entity, so a FINROC file comes back byte for byte.
//!
//! In both, characters XML 1.0 cannot carry at all (controls other than tab, newline
//! and carriage return; U+FFFE, U+FFFF) become U+FFFD: no reference can spell them,
//! and a file holding them is refused by every XML reader. `'` is never escaped: our
//! writers quote attributes with `"`, and FINROC (libxml2) writes `'` as it is, which
//! keeps FINROC files byte for byte.

use std::borrow::Cow;

/// `s` escaped for an attribute value in double quotes.
pub fn attr(s: &str) -> Cow<'_, str> {
    escape(s, Place::Attribute)
}

/// `s` escaped for element content, `>` kept readable.
pub fn text(s: &str) -> Cow<'_, str> {
    escape(s, Place::Text)
}

/// `s` escaped for element content with every `>` an entity, as libxml2 writes it.
pub fn content(s: &str) -> Cow<'_, str> {
    escape(s, Place::Content)
}

#[derive(Clone, Copy, PartialEq)]
enum Place {
    Attribute,
    Text,
    Content,
}

/// What `c` becomes at `place` (after `before`, the text written so far), or `None` to
/// keep it.
fn replacement(c: char, place: Place, before: &str) -> Option<&'static str> {
    let attribute = place == Place::Attribute;
    match c {
        '&' => Some("&amp;"),
        '<' => Some("&lt;"),
        '>' if place != Place::Text || before.ends_with("]]") => Some("&gt;"),
        '"' if attribute => Some("&quot;"),
        '\t' if attribute => Some("&#9;"),
        '\n' if attribute => Some("&#10;"),
        '\r' => Some("&#13;"),
        '\t' | '\n' => None,
        c if (c as u32) < 0x20 || c == '\u{fffe}' || c == '\u{ffff}' => Some("\u{fffd}"),
        _ => None,
    }
}

fn escape(s: &str, place: Place) -> Cow<'_, str> {
    let first = s
        .char_indices()
        .find(|&(i, c)| replacement(c, place, &s[..i]).is_some());
    let Some((start, _)) = first else {
        return Cow::Borrowed(s);
    };
    let mut out = String::with_capacity(s.len() + 16);
    out.push_str(&s[..start]);
    for (i, c) in s[start..].char_indices() {
        match replacement(c, place, &s[..start + i]) {
            Some(r) => out.push_str(r),
            None => out.push(c),
        }
    }
    Cow::Owned(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn attributes_escape_markup_quotes_and_whitespace_that_readers_normalise() {
        assert_eq!(
            attr("a<b & \"c\" > 'd'\n\te\r"),
            "a&lt;b &amp; &quot;c&quot; &gt; 'd'&#10;&#9;e&#13;"
        );
    }

    #[test]
    fn text_keeps_arrows_and_newlines_readable() {
        assert_eq!(text("in/0 -> out * 3\n\"x\"\t"), "in/0 -> out * 3\n\"x\"\t");
        assert_eq!(text("a < b && ]]> c"), "a &lt; b &amp;&amp; ]]&gt; c");
        assert_eq!(text("line\r\n"), "line&#13;\n");
    }

    #[test]
    fn content_escapes_every_closing_bracket_as_libxml2_does() {
        assert_eq!(content("a -> b < c\n\"d\""), "a -&gt; b &lt; c\n\"d\"");
    }

    #[test]
    fn characters_xml_cannot_carry_become_the_replacement_character() {
        assert_eq!(
            attr("a\u{1b}[31m\u{0}\u{ffff}"),
            "a\u{fffd}[31m\u{fffd}\u{fffd}"
        );
        assert_eq!(text("\u{7}bell"), "\u{fffd}bell");
    }

    #[test]
    fn clean_text_is_borrowed() {
        assert!(matches!(attr("robot/main"), Cow::Borrowed(_)));
        assert!(matches!(text("plain words, 'quoted'"), Cow::Borrowed(_)));
    }

    /// What is written reads back as it was through our reader (`crate::xml`), for
    /// every character XML can carry.
    #[test]
    fn written_text_reads_back_unchanged() {
        let samples = [
            "plain",
            "a<b>&\"c\"'d'",
            "two\nlines\tand\r\nreturns",
            "]]> ]]]> in/0 -> out",
            "ünïcode ✓ \u{10ffff}",
        ];
        for s in samples {
            for body in [text(s), content(s)] {
                let doc = format!("<e a=\"{}\">{body}</e>", attr(s));
                let file = ferroc_diagnostics::source::FileId(0);
                let e = crate::xml::parse(file, &doc, 8).unwrap();
                assert_eq!(e.value("a"), Some(s), "attribute of {doc}");
                assert_eq!(e.text(), s, "text of {doc}");
            }
        }
    }
}
