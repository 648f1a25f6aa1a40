//! A spanned XML tree built in one pass with quick-xml.
//!
//! The tree keeps the byte span of every element, attribute name and attribute value so
//! that any later stage can point a diagnostic at the exact place. It knows nothing about
//! the model language: vocabulary checks live in `vocabulary.rs`.

use super::name::{known_id, known_name, Name, OTHER};
use compact_str::CompactString;
use ferroc_diagnostics::source::{FileId, Span};
use quick_xml::events::{BytesRef, BytesStart, Event};
use quick_xml::Reader;

/// An attribute as a consumer sees it: its name and value, and the spans of both (the
/// value's without quotes). Made on demand from what an [`Element`] stores.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Attr<'a> {
    pub name: &'a str,
    pub value: &'a str,
    pub name_span: Span,
    pub value_span: Span,
}

/// An attribute as an element stores it: 40 bytes where a struct of two strings and two
/// spans took 72; a model of 100,000 modules has ~770,000 attributes (B1 peak memory).
/// The file comes from the element, the name of the vocabulary is a number, and the
/// value (entities resolved) is usually inline in its `CompactString`.
#[derive(Clone, Debug)]
struct StoredAttr {
    /// The value; for a name outside the vocabulary ([`OTHER`]), the name and then the
    /// value.
    text: CompactString,
    name_start: u32,
    value_start: u32,
    /// The value's length in the file (entities unresolved).
    value_len: u32,
    /// The name's length in the file (the name may have been replaced since, see
    /// [`Element::rename_attr`]).
    name_len: u16,
    /// The vocabulary's number of the name, or [`OTHER`].
    id: u16,
}

impl StoredAttr {
    fn view(&self, file: FileId) -> Attr<'_> {
        let (name, value) = if self.id == OTHER {
            self.text.split_at(usize::from(self.name_len))
        } else {
            (*known_name(self.id), self.text.as_str())
        };
        Attr {
            name,
            value,
            name_span: Span {
                file,
                start: self.name_start,
                end: self.name_start + u32::from(self.name_len),
            },
            value_span: Span {
                file,
                start: self.value_start,
                end: self.value_start + self.value_len,
            },
        }
    }

    fn has_name(&self, name: &str) -> bool {
        if self.id == OTHER {
            self.text.get(..usize::from(self.name_len)) == Some(name)
        } else {
            *known_name(self.id) == name
        }
    }
}

/// An element's character data, when it has any (most elements have none).
#[derive(Clone, Debug)]
struct Text {
    text: Box<str>,
    span: Span,
}

/// An element: its start tag, attributes, child elements and text content. 80 bytes
/// (it was 136; a model of 100,000 modules has ~370,000 elements): names of the
/// vocabulary are references, attributes and children sit in boxed slices of exactly
/// their length, and the text is boxed with its span.
#[derive(Clone, Debug)]
pub struct Element {
    pub name: Name,
    /// The tag name inside the start tag.
    pub name_span: Span,
    /// From `<` of the start tag to `>` of the end tag.
    pub span: Span,
    attrs: Box<[StoredAttr]>,
    pub children: Box<[Element]>,
    text: Option<Box<Text>>,
}

impl Element {
    pub fn attr(&self, name: &str) -> Option<Attr<'_>> {
        (self.attrs.iter())
            .find(|a| a.has_name(name))
            .map(|a| a.view(self.span.file))
    }

    pub fn value(&self, name: &str) -> Option<&str> {
        self.attr(name).map(|a| a.value)
    }

    /// Span of an attribute's value, or of the tag name when the attribute is absent.
    pub fn value_span(&self, name: &str) -> Span {
        self.attr(name).map_or(self.name_span, |a| a.value_span)
    }

    /// Attribute `index` in document order.
    pub fn attr_at(&self, index: usize) -> Option<Attr<'_>> {
        self.attrs.get(index).map(|a| a.view(self.span.file))
    }

    /// The attributes in document order.
    pub fn attrs(&self) -> impl ExactSizeIterator<Item = Attr<'_>> + '_ {
        self.attrs.iter().map(|a| a.view(self.span.file))
    }

    /// Reads attribute `index` as attribute `name` of the vocabulary from now on (the
    /// validator's recovery of a misspelt name); its spans stay those of the file.
    /// Returns false, changing nothing, when `name` is not a name of the vocabulary.
    pub fn rename_attr(&mut self, index: usize, name: &str) -> bool {
        let (Some(id), Some(attr)) = (known_id(name), self.attrs.get_mut(index)) else {
            return false;
        };
        if attr.id == OTHER {
            attr.text = CompactString::from(&attr.text[usize::from(attr.name_len)..]);
        }
        attr.id = id;
        true
    }

    /// Concatenated character data (entities resolved); whitespace before the first
    /// non-blank piece is not kept (it only separates child elements).
    pub fn text(&self) -> &str {
        self.text.as_ref().map_or("", |t| &t.text)
    }

    /// Span of the character data (first to last text byte), or the element's span
    /// when it has none (or, with child elements, only blanks between them).
    pub fn text_span(&self) -> Span {
        self.text.as_ref().map_or(self.span, |t| t.span)
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
    check_size(file, text)?;
    let mut reader = reader_of(text);
    let base = text.as_ptr() as usize;
    let offset_of = |slice: &[u8]| (slice.as_ptr() as usize).saturating_sub(base);
    let malformed = |start, end, message| malformed_at(file, text, start, end, message);
    let mut tree = Tree::default();
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
            Event::Start(tag) | Event::Empty(tag) if tree.root.is_some() => {
                let _ = tag;
                return Err(malformed(
                    before,
                    after,
                    "content after the root element: an XML file has exactly one root element"
                        .into(),
                ));
            }
            Event::Start(tag) => {
                if tree.stack.len() >= max_depth {
                    return Err(too_deep(file, before, after, max_depth));
                }
                let element =
                    start_element(file, &tag, before, after, offset_of, &mut tree.scratch)?;
                tree.open(element);
            }
            Event::Empty(tag) => {
                if tree.stack.len() >= max_depth {
                    return Err(too_deep(file, before, after, max_depth));
                }
                let element =
                    start_element(file, &tag, before, after, offset_of, &mut tree.scratch)?;
                tree.attach(element);
            }
            Event::End(_) => {
                if !tree.close(after) {
                    return Err(malformed(
                        before,
                        after,
                        "closing tag without an opening tag".into(),
                    ));
                }
            }
            Event::Text(t) => {
                let raw = t.into_inner();
                let Ok(s) = std::str::from_utf8(&raw) else {
                    return Err(malformed(before, after, "text is not valid UTF-8".into()));
                };
                add_text(&mut tree.stack, s, file, before, after, &malformed)?;
            }
            Event::CData(t) => {
                let raw = t.into_inner();
                let s = String::from_utf8_lossy(&raw).into_owned();
                add_text(&mut tree.stack, &s, file, before, after, &malformed)?;
            }
            Event::GeneralRef(r) => {
                let resolved = resolve_reference(&r).map_err(|m| malformed(before, after, m))?;
                add_text(&mut tree.stack, &resolved, file, before, after, &malformed)?;
            }
            Event::Eof => break,
            Event::Decl(_) | Event::PI(_) | Event::Comment(_) | Event::DocType(_) => {}
        }
    }
    tree.finish()
        .map_err(|m| m.unwrap_or_else(|| malformed(0, 0, "the file holds no XML element".into())))
}

/// Spans are 32-bit offsets. The loader's size limit is far below this (256 MiB by
/// default); a text given some other way is refused here rather than misplaced.
fn check_size(file: FileId, text: &str) -> Result<(), XmlError> {
    if u32::try_from(text.len()).is_err() {
        return Err(XmlError {
            span: Span::new(file, 0, 0),
            message: format!(
                "the text is {} MiB; files of 4 GiB and more cannot be read",
                text.len() >> 20
            ),
            too_deep: false,
        });
    }
    Ok(())
}

/// A reader that checks end names, reports empty elements as such and keeps all text.
fn reader_of(text: &str) -> Reader<&[u8]> {
    let mut reader = Reader::from_str(text);
    let config = reader.config_mut();
    config.check_end_names = true;
    config.expand_empty_elements = false;
    config.trim_text(false);
    reader
}

/// A syntax error from `start` to `end`. Its span ends at the end of its first line:
/// the file may not be XML at all (a `config=` or `manifest=` naming some other file),
/// and a report must show the place, not the whole file.
#[cold]
fn malformed_at(file: FileId, text: &str, start: usize, end: usize, message: String) -> XmlError {
    let end = end.max(start + 1).min(text.len().max(start));
    let line_end = (text.as_bytes().get(start..end))
        .and_then(|b| b.iter().position(|&c| c == b'\n'))
        .map_or(end, |n| start + n.max(1));
    XmlError {
        span: Span::new(file, start, line_end),
        message,
        too_deep: false,
    }
}

/// Elements nested deeper than `max_depth`.
#[cold]
fn too_deep(file: FileId, start: usize, end: usize, max_depth: usize) -> XmlError {
    XmlError {
        span: Span::new(file, start, end),
        message: format!("elements are nested more than {max_depth} deep"),
        too_deep: true,
    }
}

/// The text of a character or entity reference; `Err` says why it has none.
#[inline]
fn resolve_reference(r: &BytesRef<'_>) -> Result<String, String> {
    if r.is_char_ref() {
        match r.resolve_char_ref() {
            Ok(Some(c)) => Ok(c.to_string()),
            _ => Err("invalid character reference".into()),
        }
    } else {
        let name = String::from_utf8_lossy(r).into_owned();
        match predefined_entity(&name) {
            Some(s) => Ok(s.to_string()),
            None => Err(format!("unknown entity `&{name};`: only &amp; &lt; &gt; &quot; &apos; and character references are allowed")),
        }
    }
}

/// The tree being built. Open elements, and the children of all of them in document
/// order (`marks` says where each open element's children begin). A closed element
/// gets its children and its attributes (gathered in `scratch`) in vectors of exactly
/// their length: vectors grown by pushing would hold up to twice the room, and at
/// 100,000 modules that slack was a fifth of the checker's peak memory.
#[derive(Default)]
struct Tree {
    stack: Vec<Open>,
    marks: Vec<usize>,
    kids: Vec<Element>,
    scratch: Vec<StoredAttr>,
    root: Option<Element>,
}

impl Tree {
    /// A start tag: the element stays open until its end tag.
    #[inline]
    fn open(&mut self, element: Element) {
        self.stack.push(Open {
            element,
            text: String::new(),
            text_span: None,
        });
        self.marks.push(self.kids.len());
    }

    /// An end tag at `end`: closes the innermost open element; false when none is open.
    #[inline]
    fn close(&mut self, end: usize) -> bool {
        let Some(open) = self.stack.pop() else {
            return false;
        };
        let mark = self.marks.pop().unwrap_or(self.kids.len());
        let element = open.close(end, self.kids.drain(mark..).collect());
        self.attach(element);
        true
    }

    /// Hands a closed element to its parent (through `kids`) or makes it the root.
    #[inline]
    fn attach(&mut self, element: Element) {
        if self.stack.is_empty() {
            self.root = Some(element);
        } else {
            self.kids.push(element);
        }
    }

    /// The root once the document has ended; `Err(Some(_))` for an element never
    /// closed, `Err(None)` when there is no element at all.
    fn finish(self) -> Result<Element, Option<XmlError>> {
        if let Some(Open { element: open, .. }) = self.stack.last() {
            return Err(Some(XmlError {
                span: open.name_span,
                message: format!("element <{}> is never closed", open.name),
                too_deep: false,
            }));
        }
        self.root.ok_or(None)
    }
}

/// An element whose end tag is still to come, with its text so far.
struct Open {
    element: Element,
    text: String,
    /// From the first text byte to the last one so far, once there is text.
    text_span: Option<Span>,
}

impl Open {
    /// The element, ended at `end` with these children. Its text is kept (boxed, with
    /// its span) when it holds more than blanks, or when the element has no children:
    /// blanks between child elements are only layout, but a childless element's blank
    /// text has a place (`<param name="x"> </param>`: an empty value, shown there).
    fn close(self, end: usize, children: Box<[Element]>) -> Element {
        let Open {
            mut element,
            text,
            text_span,
        } = self;
        element.span.end = end as u32;
        if let Some(span) = text_span.filter(|_| !text.is_empty() || children.is_empty()) {
            element.text = Some(Box::new(Text {
                text: text.into_boxed_str(),
                span,
            }));
        }
        element.children = children;
        element
    }
}

fn add_text(
    stack: &mut [Open],
    s: &str,
    file: FileId,
    start: usize,
    end: usize,
    malformed: &dyn Fn(usize, usize, String) -> XmlError,
) -> Result<(), XmlError> {
    match stack.last_mut() {
        Some(parent) => {
            match &mut parent.text_span {
                Some(span) => span.end = end as u32,
                None => parent.text_span = Some(Span::new(file, start, end)),
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
    scratch: &mut Vec<StoredAttr>,
) -> Result<Element, XmlError> {
    let raw_name = tag.name().into_inner();
    let name_start = offset_of(raw_name);
    let span = Span::new(file, start, end);
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
        let Ok(name_len) = u16::try_from(key.len()) else {
            return Err(XmlError {
                span: Span::new(file, key_start, key_start + 1),
                message: format!(
                    "an attribute name of {} bytes: names are limited to 65,535 bytes",
                    key.len()
                ),
                too_deep: false,
            });
        };
        // A slice of a `&str` between ASCII delimiters: always UTF-8.
        let Ok(name) = std::str::from_utf8(key) else {
            return Err(XmlError {
                span: Span::new(file, key_start, key_start + key.len()),
                message: "an attribute name is not valid UTF-8".into(),
                too_deep: false,
            });
        };
        let id = known_id(name).unwrap_or(OTHER);
        let text = if id == OTHER {
            let mut text = CompactString::with_capacity(key.len() + value.len());
            text.push_str(name);
            text.push_str(&value);
            text
        } else {
            CompactString::from(value)
        };
        scratch.push(StoredAttr {
            text,
            // The text is at most `u32::MAX` bytes long (`parse` refuses longer ones).
            name_start: key_start as u32,
            value_start: value_start as u32,
            value_len: value_len as u32,
            name_len,
            id,
        });
    }
    Ok(Element {
        name: Name::new(std::str::from_utf8(raw_name).unwrap_or("?")),
        name_span: Span::new(file, name_start, name_start + raw_name.len()),
        span,
        // Not `mem::take`: that would hand over the scratch's spare room, and the point
        // is a slice of exactly the attributes' length (the scratch keeps its room).
        attrs: scratch.drain(..).collect(),
        children: Box::default(),
        text: None,
    })
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

mod incremental;
pub use incremental::reparse;

#[cfg(test)]
mod tests;
