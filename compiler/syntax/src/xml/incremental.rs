//! Parsing a text again after a small edit by parsing only the element the edit lies
//! in (`ferroc lsp`: a keystroke in a 2 MiB model re-parses one `<thread>`, not the
//! file). The result is the tree [`parse`] would build from the new text: the bytes
//! outside the re-parsed element are unchanged, the element's own `<` and final `>`
//! are unchanged, and its new text parsed on its own is well-formed, so a full parse
//! would meet the same events before it, inside it and after it. Whenever that cannot
//! be shown (the edit touches an element's boundary, or the element's new text is not
//! well-formed on its own) the whole text is parsed, and its error is the error.

use super::{parse, Element, XmlError};
use ferroc_diagnostics::source::{FileId, Span};

/// Makes `tree`, the tree of `old` (any file id), the tree of `new` as file `file`.
/// `Err` is [`parse`]'s error for `new` (then `tree` is left as it was).
pub fn reparse(
    tree: &mut Element,
    old: &str,
    new: &str,
    file: FileId,
    max_depth: usize,
) -> Result<(), XmlError> {
    if old == new {
        restamp(tree, file, &|x| x);
        return Ok(());
    }
    if let Some(patched) = patch(tree, old, new, file, max_depth) {
        if patched {
            return Ok(());
        }
    }
    *tree = parse(file, new, max_depth)?;
    Ok(())
}

/// Replaces the smallest element holding the edit; `None`/`Some(false)`: not possible.
fn patch(tree: &mut Element, old: &str, new: &str, file: FileId, max_depth: usize) -> Option<bool> {
    u32::try_from(new.len()).ok()?;
    let prefix = old
        .bytes()
        .zip(new.bytes())
        .take_while(|(a, b)| a == b)
        .count();
    let most = old.len().min(new.len()) - prefix;
    let suffix = old
        .bytes()
        .rev()
        .zip(new.bytes().rev())
        .take(most)
        .take_while(|(a, b)| a == b)
        .count();
    let old_end = old.len() - suffix;
    let delta = new.len() as i64 - old.len() as i64;
    // The path (child indices) to the smallest element strictly holding the edit.
    let holds = |e: &Element| (e.span.start as usize) < prefix && old_end < e.span.end as usize;
    if !holds(tree) {
        return Some(false);
    }
    let mut path = Vec::new();
    let mut here: &Element = tree;
    while let Some(i) = here.children.iter().position(holds) {
        path.push(i);
        here = &here.children[i];
    }
    let start = here.span.start as usize;
    let tag_end = start_tag_end(old, start)?;
    let in_start_tag = old_end < tag_end && old.as_bytes()[tag_end - 1] != b'/';
    let fresh = if in_start_tag {
        // An edit inside a start tag (a name, an attribute): only the tag is read
        // again; the element's content keeps its tree.
        let tag = new.get(start..=(tag_end as i64 + delta) as usize)?;
        let mut fresh = parse(file, &format!("{tag}</{}>", here.name), max_depth).ok()?;
        if !fresh.children.is_empty() || fresh.text.is_some() || fresh.name != here.name {
            return None;
        }
        restamp(&mut fresh, file, &|x| x + start as u32);
        Some(fresh)
    } else if path.is_empty() {
        return Some(false);
    } else {
        let end = (here.span.end as i64 + delta) as usize;
        let text = new.get(start..end)?;
        let mut fresh = parse(file, text, max_depth.checked_sub(path.len())?).ok()?;
        restamp(&mut fresh, file, &|x| x + start as u32);
        Some(fresh)
    };
    let shift = |x: u32| {
        if x as usize >= old_end {
            (x as i64 + delta) as u32
        } else {
            x
        }
    };
    restamp(tree, file, &shift);
    let mut slot: &mut Element = tree;
    for i in path {
        slot = &mut slot.children[i];
    }
    match fresh {
        Some(fresh) if in_start_tag => {
            slot.name = fresh.name;
            slot.name_span = fresh.name_span;
            slot.attrs = fresh.attrs;
        }
        Some(fresh) => *slot = fresh,
        None => {}
    }
    Some(true)
}

/// The offset of the `>` that ends the start tag beginning at `start` (quoted
/// attribute values may hold `>`).
fn start_tag_end(text: &str, start: usize) -> Option<usize> {
    let mut quote = None;
    for (i, b) in text.as_bytes().get(start..)?.iter().enumerate() {
        match (quote, *b) {
            (None, b'"' | b'\'') => quote = Some(*b),
            (Some(q), c) if c == q => quote = None,
            (None, b'>') => return Some(start + i),
            _ => {}
        }
    }
    None
}

/// Sets every span's file to `file` and moves every offset by `shift`.
fn restamp(e: &mut Element, file: FileId, shift: &dyn Fn(u32) -> u32) {
    let span = |s: &mut Span| {
        s.file = file;
        s.start = shift(s.start);
        s.end = shift(s.end);
    };
    span(&mut e.name_span);
    span(&mut e.span);
    if let Some(t) = &mut e.text {
        span(&mut t.span);
    }
    for a in e.attrs.iter_mut() {
        a.name_start = shift(a.name_start);
        a.value_start = shift(a.value_start);
    }
    for c in e.children.iter_mut() {
        restamp(c, file, shift);
    }
}
