//! Splicing XML text: where a start tag ends, the indentation of a line, inserting a
//! child element as its siblings are indented, removing elements with their lines,
//! escaping values. Bytes not touched stay as they were.

use ferroc_syntax::xml::Element;

/// The offset just after the `>` of `el`'s start tag.
pub(super) fn start_tag_end(text: &str, el: &Element) -> Result<usize, String> {
    let bytes = text.as_bytes();
    let mut quote = None;
    for (i, &b) in bytes.iter().enumerate().skip(el.name_span.end as usize) {
        match (quote, b) {
            (Some(q), _) if b == q => quote = None,
            (Some(_), _) => {}
            (None, b'"' | b'\'') => quote = Some(b),
            (None, b'>') => return Ok(i + 1),
            _ => {}
        }
    }
    Err(format!("the start tag of <{}> does not end", el.name))
}

/// The whitespace before `at` on its line, if only whitespace is there.
pub(super) fn indent_at(text: &str, at: usize) -> String {
    let line_start = text[..at].rfind('\n').map_or(0, |i| i + 1);
    let before = &text[line_start..at];
    match before.chars().all(|c| c == ' ' || c == '\t') {
        true => before.to_owned(),
        false => String::new(),
    }
}

/// Inserts `snippet` (lines after the first are indented as the child) as a child of
/// `parent`: after its last child of kind `after` (else its last child), indented as
/// its children are.
pub(super) fn insert_child(
    text: &str,
    parent: &Element,
    snippet: &str,
    after: &str,
) -> Result<String, String> {
    let anchor = (parent.children.iter().rev())
        .find(|c| c.name == after)
        .or_else(|| parent.children.last());
    let parent_indent = indent_at(text, parent.span.start as usize);
    let indent = match anchor {
        Some(c) => indent_at(text, c.span.start as usize),
        None => format!("{parent_indent}  "),
    };
    let body = snippet.replace('\n', &format!("\n{indent}"));
    let mut new = text.to_owned();
    match anchor {
        Some(c) => new.insert_str(c.span.end as usize, &format!("\n{indent}{body}")),
        None => {
            let end = start_tag_end(text, parent)?;
            if text[..end].ends_with("/>") {
                let tag = format!(">\n{indent}{body}\n{parent_indent}</{}>", parent.name);
                new.replace_range(end - 2..end, &tag);
            } else {
                new.insert_str(end, &format!("\n{indent}{body}"));
            }
        }
    }
    Ok(new)
}

/// Removes the spans, each with the whitespace before it on its line (and the line
/// break, when nothing else is left on the line).
pub(super) fn remove_spans(text: &str, mut spans: Vec<(usize, usize)>) -> String {
    spans.sort();
    spans.dedup();
    let mut new = text.to_owned();
    let mut limit = text.len();
    for (start, end) in spans.into_iter().rev() {
        if end > limit {
            continue;
        }
        let line_start = text[..start].rfind('\n').map_or(0, |i| i + 1);
        let blank_before = text[line_start..start].trim().is_empty();
        let line_end = text[end..].find('\n').map_or(text.len(), |i| end + i);
        let blank_after = text[end..line_end].trim().is_empty();
        let (from, to) = match (blank_before, blank_after) {
            (true, true) if line_start > 0 => (line_start - 1, line_end),
            (true, _) => (line_start, end),
            _ => (start, end),
        };
        let to = to.min(limit);
        new.replace_range(from..to, "");
        limit = from;
    }
    new
}
