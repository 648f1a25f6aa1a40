//! A spanned XML tree built in one pass with quick-xml.
//!
//! The tree keeps the byte span of every element, attribute name and attribute value so
//! that any later stage can point a diagnostic at the exact place. It knows nothing about
//! the model language: vocabulary checks live in `vocabulary.rs`.

use crate::source::{FileId, Span};
use compact_str::CompactString;
use quick_xml::events::{BytesStart, Event};
use quick_xml::Reader;

/// An attribute with the spans of its name and of its value (without quotes).
///
/// Names and values are `CompactString`s: almost all of them fit inline (24 bytes), so a
/// model of 100,000 modules is read without millions of small allocations.
#[derive(Clone, Debug)]
pub struct Attr {
    pub name: CompactString,
    pub value: CompactString,
    pub name_span: Span,
    pub value_span: Span,
}

/// An element: its start tag, attributes, child elements and text content.
#[derive(Clone, Debug)]
pub struct Element {
    pub name: CompactString,
    /// The tag name inside the start tag.
    pub name_span: Span,
    /// From `<` of the start tag to `>` of the end tag.
    pub span: Span,
    pub attrs: Vec<Attr>,
    pub children: Vec<Element>,
    /// Concatenated character data (entities resolved); whitespace before the first
    /// non-blank piece is not kept (it only separates child elements).
    pub text: String,
    /// Span of the character data (first to last text byte), or the element's span.
    pub text_span: Span,
}

impl Element {
    pub fn attr(&self, name: &str) -> Option<&Attr> {
        self.attrs.iter().find(|a| a.name == name)
    }

    pub fn value(&self, name: &str) -> Option<&str> {
        self.attr(name).map(|a| a.value.as_str())
    }

    /// Span of an attribute's value, or of the tag name when the attribute is absent.
    pub fn value_span(&self, name: &str) -> Span {
        self.attr(name).map_or(self.name_span, |a| a.value_span)
    }

    pub fn children_named<'a>(&'a self, name: &'a str) -> impl Iterator<Item = &'a Element> + 'a {
        self.children.iter().filter(move |c| c.name == name)
    }
}

/// Why a file could not be read as an XML tree.
#[derive(Debug)]
pub struct XmlError {
    pub span: Span,
    pub message: String,
    pub too_deep: bool,
}

/// Parses one document. `max_depth` bounds element nesting.
pub fn parse(file: FileId, text: &str, max_depth: usize) -> Result<Element, XmlError> {
    let mut reader = Reader::from_str(text);
    let config = reader.config_mut();
    config.check_end_names = true;
    config.expand_empty_elements = false;
    config.trim_text(false);
    let base = text.as_ptr() as usize;
    let offset_of = |slice: &[u8]| (slice.as_ptr() as usize).saturating_sub(base);
    // The span of a syntax error ends at the end of its first line: the file may not be
    // XML at all (a `config=` or `manifest=` naming some other file), and a report must
    // show the place, not the whole file.
    let malformed = |start: usize, end: usize, message: String| {
        let end = end.max(start + 1).min(text.len().max(start));
        let line_end = (text.as_bytes().get(start..end))
            .and_then(|b| b.iter().position(|&c| c == b'\n'))
            .map_or(end, |n| start + n.max(1));
        XmlError {
            span: Span::new(file, start, line_end),
            message,
            too_deep: false,
        }
    };

    // Open elements, and the children of all of them in document order (`marks` says
    // where each open element's children begin). A closed element gets its children
    // and its attributes (gathered in `scratch`) in vectors of exactly their length:
    // vectors grown by pushing would hold up to twice the room, and at 100,000 modules
    // that slack was a fifth of the checker's peak memory.
    let mut stack: Vec<Element> = Vec::new();
    let mut marks: Vec<usize> = Vec::new();
    let mut kids: Vec<Element> = Vec::new();
    let mut scratch: Vec<Attr> = Vec::new();
    let mut root: Option<Element> = None;
    loop {
        let before = reader.buffer_position() as usize;
        let event = match reader.read_event() {
            Ok(e) => e,
            Err(err) => {
                let at = reader.error_position() as usize;
                return Err(malformed(at, at + 1, describe(&err)));
            }
        };
        let after = reader.buffer_position() as usize;
        match event {
            Event::Start(tag) | Event::Empty(tag) if root.is_some() => {
                let _ = tag;
                return Err(malformed(
                    before,
                    after,
                    "content after the root element: an XML file has exactly one root element"
                        .into(),
                ));
            }
            Event::Start(tag) => {
                if stack.len() >= max_depth {
                    return Err(XmlError {
                        span: Span::new(file, before, after),
                        message: format!("elements are nested more than {max_depth} deep"),
                        too_deep: true,
                    });
                }
                stack.push(start_element(
                    file,
                    &tag,
                    before,
                    after,
                    offset_of,
                    &mut scratch,
                )?);
                marks.push(kids.len());
            }
            Event::Empty(tag) => {
                if stack.len() >= max_depth {
                    return Err(XmlError {
                        span: Span::new(file, before, after),
                        message: format!("elements are nested more than {max_depth} deep"),
                        too_deep: true,
                    });
                }
                let element = start_element(file, &tag, before, after, offset_of, &mut scratch)?;
                attach(&stack, &mut kids, &mut root, element);
            }
            Event::End(_) => {
                let Some(mut element) = stack.pop() else {
                    return Err(malformed(
                        before,
                        after,
                        "closing tag without an opening tag".into(),
                    ));
                };
                element.span.end = after as u32;
                let mark = marks.pop().unwrap_or(kids.len());
                element.children = kids.drain(mark..).collect();
                attach(&stack, &mut kids, &mut root, element);
            }
            Event::Text(t) => {
                let raw = t.into_inner();
                let Ok(s) = std::str::from_utf8(&raw) else {
                    return Err(malformed(before, after, "text is not valid UTF-8".into()));
                };
                add_text(&mut stack, s, file, before, after, &malformed)?;
            }
            Event::CData(t) => {
                let raw = t.into_inner();
                let s = String::from_utf8_lossy(&raw).into_owned();
                add_text(&mut stack, &s, file, before, after, &malformed)?;
            }
            Event::GeneralRef(r) => {
                let resolved = if r.is_char_ref() {
                    match r.resolve_char_ref() {
                        Ok(Some(c)) => c.to_string(),
                        _ => {
                            return Err(malformed(
                                before,
                                after,
                                "invalid character reference".into(),
                            ))
                        }
                    }
                } else {
                    let name = String::from_utf8_lossy(&r).into_owned();
                    match predefined_entity(&name) {
                        Some(s) => s.to_string(),
                        None => {
                            return Err(malformed(
                                before,
                                after,
                                format!("unknown entity `&{name};`: only &amp; &lt; &gt; &quot; &apos; and character references are allowed"),
                            ))
                        }
                    }
                };
                add_text(&mut stack, &resolved, file, before, after, &malformed)?;
            }
            Event::Eof => break,
            Event::Decl(_) | Event::PI(_) | Event::Comment(_) | Event::DocType(_) => {}
        }
    }
    if let Some(open) = stack.last() {
        return Err(XmlError {
            span: open.name_span,
            message: format!("element <{}> is never closed", open.name),
            too_deep: false,
        });
    }
    root.ok_or_else(|| malformed(0, 0, "the file holds no XML element".into()))
}

/// Hands a closed element to its parent (through `kids`) or makes it the root.
fn attach(
    stack: &[Element],
    kids: &mut Vec<Element>,
    root: &mut Option<Element>,
    element: Element,
) {
    if stack.is_empty() {
        *root = Some(element);
    } else {
        kids.push(element);
    }
}

fn add_text(
    stack: &mut [Element],
    s: &str,
    file: FileId,
    start: usize,
    end: usize,
    malformed: &dyn Fn(usize, usize, String) -> XmlError,
) -> Result<(), XmlError> {
    match stack.last_mut() {
        Some(parent) => {
            if parent.text.is_empty() && parent.text_span == parent.span {
                parent.text_span = Span::new(file, start, end);
            } else {
                parent.text_span.end = end as u32;
            }
            // Indentation between child elements is not content; skipping it saves an
            // allocation for every element that has children.
            if !(parent.text.is_empty() && s.trim().is_empty()) {
                parent.text.push_str(s);
            }
            Ok(())
        }
        None if s.trim().is_empty() => Ok(()),
        None => Err(malformed(
            start,
            end,
            "text outside the root element".into(),
        )),
    }
}

fn start_element(
    file: FileId,
    tag: &BytesStart<'_>,
    start: usize,
    end: usize,
    offset_of: impl Fn(&[u8]) -> usize,
    scratch: &mut Vec<Attr>,
) -> Result<Element, XmlError> {
    let raw_name = tag.name().into_inner();
    let name_start = offset_of(raw_name);
    let name = CompactString::from(std::str::from_utf8(raw_name).unwrap_or("?"));
    let span = Span::new(file, start, end);
    let mut element = Element {
        name,
        name_span: Span::new(file, name_start, name_start + raw_name.len()),
        span,
        attrs: Vec::new(),
        children: Vec::new(),
        text: String::new(),
        text_span: span,
    };
    scratch.clear();
    let mut attributes = tag.attributes();
    // Duplicates are reported by the vocabulary check with both places, not here.
    attributes.with_checks(false);
    for attr in attributes {
        let attr = attr.map_err(|e| XmlError {
            span,
            message: format!("malformed attribute: {e}"),
            too_deep: false,
        })?;
        let key = attr.key.into_inner();
        let key_start = offset_of(key);
        let value_start = offset_of(&attr.value);
        let value_len = attr.value.len();
        let value = attr.unescape_value().map_err(|e| XmlError {
            span: Span::new(file, value_start, value_start + value_len),
            message: format!("malformed attribute value: {e}"),
            too_deep: false,
        })?;
        scratch.push(Attr {
            name: CompactString::from_utf8_lossy(key),
            value: CompactString::from(value),
            name_span: Span::new(file, key_start, key_start + key.len()),
            value_span: Span::new(file, value_start, value_start + value_len),
        });
    }
    // Not `mem::take`: that would hand over the scratch's spare room, and the point is
    // a vector of exactly the attributes' length (the scratch keeps its room).
    #[allow(clippy::drain_collect)]
    let attrs: Vec<Attr> = scratch.drain(..).collect();
    element.attrs = attrs;
    Ok(element)
}

fn predefined_entity(name: &str) -> Option<&'static str> {
    Some(match name {
        "amp" => "&",
        "lt" => "<",
        "gt" => ">",
        "quot" => "\"",
        "apos" => "'",
        _ => return None,
    })
}

/// quick-xml's error text, reworded where it helps a person.
fn describe(err: &quick_xml::Error) -> String {
    use quick_xml::errors::SyntaxError;
    match err {
        quick_xml::Error::IllFormed(e) => format!("ill-formed XML: {e}"),
        quick_xml::Error::Syntax(SyntaxError::UnclosedTag) => "a tag is not closed with `>`".into(),
        quick_xml::Error::Syntax(e) => format!("XML syntax error: {e}"),
        other => format!("XML error: {other}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_ok(text: &str) -> Element {
        parse(FileId(0), text, 64).expect("well-formed")
    }

    #[test]
    fn spans_point_at_names_and_values() {
        let text = "<a x=\"1\">\n  <b y='two' />t&amp;u</a>";
        let a = parse_ok(text);
        let x = a.attr("x").unwrap();
        assert_eq!(
            &text[x.name_span.start as usize..x.name_span.end as usize],
            "x"
        );
        assert_eq!(
            &text[x.value_span.start as usize..x.value_span.end as usize],
            "1"
        );
        let b = &a.children[0];
        assert_eq!(
            &text[b.name_span.start as usize..b.name_span.end as usize],
            "b"
        );
        assert_eq!(b.value("y"), Some("two"));
        assert_eq!(a.text.trim(), "t&u");
        assert_eq!(a.span.end as usize, text.len());
    }

    #[test]
    fn malformed_input_is_an_error_with_a_place() {
        for bad in [
            "<a><b></a>",
            "<a",
            "<a x=1/>",
            "",
            "<a/><b/>",
            "<a>&foo;</a>",
            "text",
        ] {
            let err = parse(FileId(0), bad, 64).unwrap_err();
            assert!(!err.message.is_empty(), "{bad}");
            assert!(err.span.start as usize <= bad.len(), "{bad}");
        }
    }

    /// Attributes and children sit in vectors of exactly their length (B1: vectors
    /// grown by pushing held up to twice the room), in document order.
    #[test]
    fn vectors_hold_no_spare_room() {
        let text = "<a p=\"1\" q=\"2\" r=\"3\" s=\"4\" t=\"5\">\
                    <b x=\"1\"/><c><d/><d/><d/><d/><d/></c><b/><b/><b/><b/></a>";
        let a = parse_ok(text);
        let names = |e: &Element| {
            e.children
                .iter()
                .map(|c| c.name.to_string())
                .collect::<Vec<_>>()
        };
        assert_eq!(names(&a), ["b", "c", "b", "b", "b", "b"]);
        assert_eq!(names(&a.children[1]), ["d"; 5]);
        let attrs: Vec<&str> = a.attrs.iter().map(|x| x.name.as_str()).collect();
        assert_eq!(attrs, ["p", "q", "r", "s", "t"]);
        fn exact(e: &Element) {
            assert_eq!(e.attrs.capacity(), e.attrs.len(), "<{}> attributes", e.name);
            assert_eq!(
                e.children.capacity(),
                e.children.len(),
                "<{}> children",
                e.name
            );
            e.children.iter().for_each(exact);
        }
        exact(&a);
    }

    #[test]
    fn depth_is_limited() {
        let text = "<a>".repeat(100) + &"</a>".repeat(100);
        assert!(parse(FileId(0), &text, 50).unwrap_err().too_deep);
        assert!(parse(FileId(0), &text, 200).is_ok());
    }
}
