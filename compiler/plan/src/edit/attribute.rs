//! The small edits of `ferroc lsp`'s quick fixes: set, remove or swap one attribute of
//! the element a finding points into, and add one element to the root. Like the
//! operations of `text.rs`, every byte not touched stays as it was.

use super::splice::{indent_at, insert_child, remove_spans};
use super::text::parse;
use ferroc_syntax::escape::attr;
use ferroc_syntax::xml::Element;

/// The innermost `<tag>` element whose text holds the byte `at`.
fn innermost<'a>(el: &'a Element, tag: &str, at: usize) -> Option<&'a Element> {
    let inside = |e: &Element| e.span.start as usize <= at && at < e.span.end as usize;
    if !inside(el) {
        return None;
    }
    let deeper = el.children.iter().find_map(|c| innermost(c, tag, at));
    deeper.or_else(|| (el.name == tag).then_some(el))
}

/// Sets attribute `name` of the innermost `<tag>` element around the byte `at` to
/// `value`, or removes it (`None`): the one attribute edit, for the quick fixes of
/// `ferroc lsp` (`delay="1"` on the `<connect>` a finding points into). A value that
/// is written already is replaced in place (its quotes kept); a new attribute goes
/// after the last one — on a line of its own, indented as that one, when the
/// attributes stand one per line. An element that removing its only attribute would
/// leave saying nothing (no attribute, child or text: `<convert scale="100"/>`) goes
/// with its line. Every other byte stays as it was.
pub fn set_attribute(
    text: &str,
    tag: &str,
    at: usize,
    name: &str,
    value: Option<&str>,
) -> Result<String, String> {
    let root = parse(text)?;
    let el = innermost(&root, tag, at).ok_or_else(|| format!("no <{tag}> is at byte {at}"))?;
    let mut new = text.to_owned();
    match (el.attr(name), value) {
        (Some(a), Some(v)) => {
            let span = a.value_span.start as usize..a.value_span.end as usize;
            new.replace_range(span, &attr(v));
        }
        (Some(_), None)
            if el.attrs().len() == 1 && el.children.is_empty() && el.text().is_empty() =>
        {
            new = remove_spans(text, vec![(el.span.start as usize, el.span.end as usize)]);
        }
        (Some(a), None) => {
            // The attribute with the blanks before it; its closing quote is one byte.
            let end = a.value_span.end as usize + 1;
            let start = text[..a.name_span.start as usize].trim_end().len();
            new.replace_range(start..end, "");
        }
        (None, Some(v)) => {
            let (sep, after) = new_attribute_place(text, el);
            new.insert_str(after, &format!("{sep}{name}=\"{}\"", attr(v)));
        }
        (None, None) => return Err(format!("<{tag}> has no `{name}` to remove")),
    }
    Ok(new)
}

/// Inserts `snippet` (one element) as a child of the document's root element: after
/// its last `<after>` child, else after its last child, indented as its children are
/// (the `<use library>` a file lacks).
pub fn add_to_root(text: &str, snippet: &str, after: &str) -> Result<String, String> {
    let root = parse(text)?;
    insert_child(text, &root, snippet, after)
}

/// Swaps the values of attributes `a` and `b` of the innermost `<tag>` element around
/// the byte `at` (`from` and `to` of a connection written the wrong way round).
pub fn swap_attributes(
    text: &str,
    tag: &str,
    at: usize,
    a: &str,
    b: &str,
) -> Result<String, String> {
    let root = parse(text)?;
    let el = innermost(&root, tag, at).ok_or_else(|| format!("no <{tag}> is at byte {at}"))?;
    let (Some(x), Some(y)) = (el.attr(a), el.attr(b)) else {
        return Err(format!("<{tag}> lacks `{a}` or `{b}`"));
    };
    let raw = |s: ferroc_diagnostics::source::Span| &text[s.start as usize..s.end as usize];
    let mut parts = [
        (x.value_span, raw(y.value_span)),
        (y.value_span, raw(x.value_span)),
    ];
    parts.sort_by_key(|(s, _)| std::cmp::Reverse(s.start));
    let mut new = text.to_owned();
    for (span, value) in parts {
        new.replace_range(span.start as usize..span.end as usize, value);
    }
    Ok(new)
}

/// Where a new attribute of `el` goes (after its last attribute, else after its name)
/// and what separates it from that: a line break and the last attribute's indentation
/// when that one starts a line, else a space.
fn new_attribute_place(text: &str, el: &Element) -> (String, usize) {
    let Some(last) = el.attrs().last() else {
        return (" ".into(), el.name_span.end as usize);
    };
    let after = last.value_span.end as usize + 1;
    let own_line = text[..last.name_span.start as usize]
        .rsplit('\n')
        .next()
        .is_some_and(|before| before.trim().is_empty());
    let sep = match own_line {
        true => format!("\n{}", indent_at(text, last.name_span.start as usize)),
        false => " ".into(),
    };
    (sep, after)
}

#[cfg(test)]
mod tests {
    use super::*;

    const MODEL: &str = r#"<application name="a" version="1">
  <!-- the loop -->
  <connect from="p/t/a/out" to="p/t/b/in"/>   <!-- keep me -->
  <connect from="p/t/b/out"
           to="p/t/a/in"
           queue='4'>
    <convert scale="100"/>
  </connect>
</application>
"#;

    fn at(needle: &str) -> usize {
        MODEL.find(needle).expect("in the model")
    }

    #[test]
    fn a_new_attribute_follows_the_last_on_its_line() {
        let new = set_attribute(MODEL, "connect", at("p/t/b/in"), "delay", Some("1")).unwrap();
        let want = MODEL.replace(
            r#"to="p/t/b/in"/>   <!-- keep me -->"#,
            r#"to="p/t/b/in" delay="1"/>   <!-- keep me -->"#,
        );
        assert_eq!(new, want);
    }

    #[test]
    fn a_new_attribute_gets_a_line_when_they_stand_one_per_line() {
        let new = set_attribute(
            MODEL,
            "connect",
            at("p/t/a/in"),
            "on-full",
            Some("drop-oldest"),
        )
        .unwrap();
        let want = MODEL.replace(
            "           queue='4'>",
            "           queue='4'\n           on-full=\"drop-oldest\">",
        );
        assert_eq!(new, want);
    }

    #[test]
    fn a_written_value_is_replaced_in_its_quotes_and_escaped() {
        let new = set_attribute(MODEL, "connect", at("queue"), "queue", Some("8")).unwrap();
        assert_eq!(new, MODEL.replace("queue='4'", "queue='8'"));
        let new = set_attribute(MODEL, "connect", at("p/t/b/in"), "to", Some("x\"y")).unwrap();
        assert_eq!(new, MODEL.replace("to=\"p/t/b/in\"", "to=\"x&quot;y\""));
    }

    #[test]
    fn removing_takes_the_blanks_before_the_attribute() {
        let new = set_attribute(MODEL, "connect", at("queue"), "queue", None).unwrap();
        assert_eq!(
            new,
            MODEL.replace("\"p/t/a/in\"\n           queue='4'>", "\"p/t/a/in\">")
        );
        let err = set_attribute(MODEL, "connect", at("p/t/b/in"), "queue", None).unwrap_err();
        assert!(err.contains("no `queue`"), "{err}");
    }

    #[test]
    fn the_innermost_element_of_the_tag_is_edited() {
        // `<convert/>` would say nothing: the step goes with its line.
        let new = set_attribute(MODEL, "convert", at("scale"), "scale", None).unwrap();
        assert_eq!(new, MODEL.replace("\n    <convert scale=\"100\"/>", ""));
        // Outside any <connect> (the comment): nothing to edit.
        let err = set_attribute(MODEL, "connect", at("the loop"), "delay", Some("1"));
        assert!(err.unwrap_err().contains("no <connect>"));
    }

    #[test]
    fn a_root_child_goes_after_its_kind_with_their_indentation() {
        let text = "<application name=\"a\">\n    <use library=\"nav\"/>\n    <!-- n -->\n    <part name=\"p\"/>\n</application>\n";
        let new = add_to_root(text, "<use library=\"geometry\"/>", "use").unwrap();
        let want = text.replace(
            "<use library=\"nav\"/>\n",
            "<use library=\"nav\"/>\n    <use library=\"geometry\"/>\n",
        );
        assert_eq!(new, want);
    }

    #[test]
    fn swapping_keeps_the_raw_values_and_the_layout() {
        let new = swap_attributes(MODEL, "connect", at("p/t/a/in"), "from", "to").unwrap();
        let want = MODEL.replace(
            "from=\"p/t/b/out\"\n           to=\"p/t/a/in\"",
            "from=\"p/t/a/in\"\n           to=\"p/t/b/out\"",
        );
        assert_eq!(new, want);
    }
}
