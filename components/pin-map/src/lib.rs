//! The pin map of `ferroc_std.Filter` (FlexiFilter): which input element feeds which
//! output element, scaled, offset and cast. One parser for the two readers: the model
//! checker (check P108, with spans into the parameter's text) and the module itself.
//!
//! ```text
//! in/0 -> out[0] * 1000 as i32; in/1 -> out[1] * 1000 as i32
//! in/2[1] -> out/1 * 0.001 + 5
//! ```
//!
//! Entries are separated by `;` or line breaks. A pin is a port name (`in/0`, `out`)
//! with an optional element index (`[2]`). After the arrow: an optional scale (`* N`),
//! an optional offset (`+ N` or `- N`), and an optional cast (`as TYPE`), which a
//! conversion that loses data must name (`f64` → `i32`). `out = in · scale + offset`.

#![forbid(unsafe_code)]

use std::ops::Range;

/// One end of a mapping: a port and perhaps an element of it.
#[derive(Clone, Debug, PartialEq)]
pub struct Pin<'a> {
    pub port: &'a str,
    pub index: Option<usize>,
    /// Where it is written, in bytes of the map's text.
    pub span: Range<usize>,
}

/// One mapping: `from -> to * scale + offset as cast`.
#[derive(Clone, Debug, PartialEq)]
pub struct Entry<'a> {
    pub from: Pin<'a>,
    pub to: Pin<'a>,
    pub scale: f64,
    pub offset: f64,
    /// The named element type and where it is written.
    pub cast: Option<(&'a str, Range<usize>)>,
    pub span: Range<usize>,
}

/// A map that does not parse: what and where (bytes of the text).
#[derive(Clone, Debug, PartialEq)]
pub struct MapError {
    pub what: String,
    pub span: Range<usize>,
}

/// Maps longer than this are refused (a model cannot make the parser work without end).
pub const MAX_ENTRIES: usize = 4096;

/// Parses a whole map.
pub fn parse(text: &str) -> Result<Vec<Entry<'_>>, MapError> {
    let mut entries = Vec::new();
    let mut start = 0;
    for piece in text.split([';', '\n']) {
        let at = start;
        start += piece.len() + 1;
        if piece.trim().is_empty() {
            continue;
        }
        if entries.len() == MAX_ENTRIES {
            return Err(MapError {
                what: format!("more than {MAX_ENTRIES} entries"),
                span: at..at + piece.len(),
            });
        }
        entries.push(entry(piece, at)?);
    }
    if entries.is_empty() {
        return Err(MapError {
            what: "the map is empty: write entries like `in/0 -> out[0]`".into(),
            span: 0..text.len(),
        });
    }
    Ok(entries)
}

/// Words of `piece` with their offsets; `[…]` stays with its port, operators apart.
fn tokens(piece: &str, base: usize) -> Vec<(&str, Range<usize>)> {
    let mut out = Vec::new();
    let mut i = 0;
    let next_len = |i: usize| piece[i..].chars().next().map_or(1, char::len_utf8);
    while let Some(c) = piece[i..].chars().next() {
        if c.is_whitespace() {
            i += c.len_utf8();
            continue;
        }
        let begin = i;
        if piece[i..].starts_with("->") {
            i += 2;
        } else if c == '*' || c == '+' {
            i += 1;
        } else {
            while let Some(c) = piece[i..].chars().next() {
                if c.is_whitespace() || c == '*' || c == '+' || piece[i..].starts_with("->") {
                    break;
                }
                i += next_len(i);
            }
        }
        out.push((&piece[begin..i], base + begin..base + i));
    }
    out
}

fn entry(piece: &str, base: usize) -> Result<Entry<'_>, MapError> {
    let span = base + (piece.len() - piece.trim_start().len())..base + piece.trim_end().len();
    let toks = tokens(piece, base);
    let err = |what: String, span: Range<usize>| MapError { what, span };
    let mut it = toks.into_iter().peekable();
    let (from, arrow) = (it.next(), it.next());
    let (Some(from), Some(("->", _))) = (from.clone(), arrow.clone()) else {
        return Err(err(
            "write `INPUT -> OUTPUT`, e.g. `in/0 -> out[1] * 1000 as i32`".into(),
            span,
        ));
    };
    let Some(to) = it.next() else {
        return Err(err("the output pin after `->` is missing".into(), span));
    };
    let mut e = Entry {
        from: pin(from.0, from.1)?,
        to: pin(to.0, to.1)?,
        scale: 1.0,
        offset: 0.0,
        cast: None,
        span: span.clone(),
    };
    let number = |t: Option<(&str, Range<usize>)>, after: &str| -> Result<f64, MapError> {
        let Some((text, at)) = t else {
            return Err(err(
                format!("a number is missing after `{after}`"),
                span.clone(),
            ));
        };
        match text.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            _ => Err(err(format!("`{text}` is not a finite number"), at)),
        }
    };
    if it.peek().is_some_and(|(t, _)| *t == "*") {
        it.next();
        e.scale = number(it.next(), "*")?;
    }
    match it.peek().map(|(t, _)| *t) {
        Some("+") => {
            it.next();
            e.offset = number(it.next(), "+")?;
        }
        // `- 5` arrives as one word with its number (`-` is not an operator token).
        Some(t) if t.starts_with('-') && t != "->" => {
            let (text, at) = it.next().unwrap_or_default();
            let rest = text.trim_start_matches('-');
            e.offset = -if rest.is_empty() {
                number(it.next(), "-")?
            } else {
                number(Some((rest, at)), "-")?
            };
        }
        _ => {}
    }
    if it.peek().is_some_and(|(t, _)| *t == "as") {
        it.next();
        let Some((ty, at)) = it.next() else {
            return Err(err("a type is missing after `as`".into(), span));
        };
        e.cast = Some((ty, at));
    }
    if let Some((extra, at)) = it.next() {
        return Err(err(
            format!("unexpected `{extra}`: after the pins come `* SCALE`, `+ OFFSET`, `as TYPE`"),
            at,
        ));
    }
    Ok(e)
}

fn pin(text: &str, span: Range<usize>) -> Result<Pin<'_>, MapError> {
    let bad = |what: String| MapError {
        what,
        span: span.clone(),
    };
    let (port, index) = match text.find('[') {
        None => (text, None),
        Some(open) => {
            let inner = text[open + 1..]
                .strip_suffix(']')
                .ok_or_else(|| bad(format!("`{text}`: close the index with `]`")))?;
            let k: usize = inner.parse().map_err(|_| {
                bad(format!(
                    "`{text}`: the index `{inner}` is not a whole number"
                ))
            })?;
            (&text[..open], Some(k))
        }
    };
    let valid = |c: char| c.is_ascii_alphanumeric() || c == '_' || c == '/';
    if port.is_empty() || !port.chars().all(valid) {
        return Err(bad(format!("`{text}` is not a port name (`in/0`, `out`)")));
    }
    Ok(Pin { port, index, span })
}

/// What a port of a model type holds, element-wise: numbers of one `element` type,
/// `len` of them (`None`: a vector, any number).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shape<'a> {
    pub element: &'a str,
    pub len: Option<usize>,
    /// A single number, not an array of one.
    pub scalar: bool,
}

const NUMBERS: [&str; 10] = [
    "f64", "f32", "i8", "i16", "i32", "i64", "u8", "u16", "u32", "u64",
];

/// The shape of `model_type` (`f64`, `f64[3]`, `f64[4][4]`, `[u8]`); `None` if it is
/// not numbers.
pub fn shape(model_type: &str) -> Option<Shape<'_>> {
    let number = |t: &str| NUMBERS.contains(&t);
    if let Some(inner) = model_type
        .strip_prefix('[')
        .and_then(|t| t.strip_suffix(']'))
    {
        return number(inner).then_some(Shape {
            element: inner,
            len: None,
            scalar: false,
        });
    }
    let (element, dims) = model_type.split_at(model_type.find('[').unwrap_or(model_type.len()));
    if !number(element) {
        return None;
    }
    let mut len = 1usize;
    if !dims.is_empty() {
        for d in dims.strip_prefix('[')?.strip_suffix(']')?.split("][") {
            len = len.checked_mul(d.parse().ok()?)?;
        }
    }
    Some(Shape {
        element,
        len: Some(len),
        scalar: dims.is_empty(),
    })
}

/// Whether converting numbers of type `from` to `to` can lose data: floats to
/// integers, `f64` to `f32`, wider to narrower or signed to unsigned integers (the
/// checker asks for an explicit `as` then).
pub fn loses_data(from: &str, to: &str) -> bool {
    let bits = |t: &str| t[1..].parse::<u32>().unwrap_or(64);
    let float = |t: &str| t.starts_with('f');
    match (float(from), float(to)) {
        (_, true) if from == to => false,
        (true, true) => bits(to) < bits(from),
        (true, false) => true,
        // Integers into f64 are exact below 2^53; i64/u64 are not always.
        (false, true) => bits(from) > if to == "f32" { 16 } else { 32 },
        (false, false) => {
            let (fs, ts) = (from.starts_with('i'), to.starts_with('i'));
            match (fs, ts) {
                (true, false) => true,
                (false, true) => bits(to) <= bits(from),
                _ => bits(to) < bits(from),
            }
        }
    }
}

/// Whether a port is an input or an output of the filter.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dir {
    In,
    Out,
}

/// A mapping that does not fit the ports: what, where, and how to fix it.
#[derive(Clone, Debug, PartialEq)]
pub struct Misfit {
    pub what: String,
    pub span: Range<usize>,
    pub help: String,
}

/// Checks `entries` against the filter's ports (`port(name)`: its direction and model
/// type): pins exist with the right direction, carry numbers, indices lie in range,
/// whole ports map onto ports of the same length, conversions that lose data name
/// their `as` type (and only the destination's element type), no output element is
/// written twice.
pub fn validate<'t, 'p>(
    entries: &[Entry<'t>],
    port: impl Fn(&str) -> Option<(Dir, &'p str)>,
) -> Vec<Misfit> {
    let mut out = Vec::new();
    let mut written: Vec<(&str, Option<usize>)> = Vec::new();
    for e in entries {
        let mut shapes = Vec::new();
        for (pin, want) in [(&e.from, Dir::In), (&e.to, Dir::Out)] {
            let misfit = |what: String, help: &str| Misfit {
                what,
                span: pin.span.clone(),
                help: help.to_owned(),
            };
            let Some((dir, ty)) = port(pin.port) else {
                out.push(misfit(
                    format!("the filter has no port `{}`", pin.port),
                    "map declared ports: in/0, in/1, … or out/0, … (or the group name without count)",
                ));
                continue;
            };
            if dir != want {
                out.push(misfit(
                    format!(
                        "`{}` is an {}, but stands {} the arrow",
                        pin.port,
                        if dir == Dir::In { "input" } else { "output" },
                        if want == Dir::In { "before" } else { "after" }
                    ),
                    "write `INPUT -> OUTPUT`",
                ));
                continue;
            }
            let Some(sh) = shape(ty) else {
                out.push(misfit(
                    format!("`{}` carries `{ty}`, which is not numbers", pin.port),
                    "a filter maps numbers, vectors and arrays of numbers",
                ));
                continue;
            };
            match (pin.index, sh.len) {
                (Some(_), _) if sh.scalar => out.push(misfit(
                    format!(
                        "`{}` is a single `{ty}`: it has no elements to index",
                        pin.port
                    ),
                    "drop the index",
                )),
                (Some(k), Some(n)) if k >= n => out.push(misfit(
                    format!(
                        "index {k} is out of range: `{}` (`{ty}`) has {n} elements",
                        pin.port
                    ),
                    &format!("use an index from 0 to {}", n - 1),
                )),
                _ => {}
            }
            shapes.push(sh);
        }
        let [from, to] = shapes[..] else { continue };
        let whole = |p: &Pin<'_>, s: Shape<'_>| p.index.is_none() && !s.scalar;
        if whole(&e.from, from) != whole(&e.to, to) || (whole(&e.from, from) && from.len != to.len)
        {
            out.push(Misfit {
                what: "a whole array maps only onto a whole array of the same length".into(),
                span: e.span.clone(),
                help: "map single elements (`in/0[2] -> out[0]`), or ports of one length".into(),
            });
        }
        match &e.cast {
            Some((ty, span)) if *ty != to.element => out.push(Misfit {
                what: format!(
                    "`as {ty}`, but `{}` holds `{}` elements",
                    e.to.port, to.element
                ),
                span: span.clone(),
                help: format!("write `as {}`", to.element),
            }),
            None if loses_data(from.element, to.element) => out.push(Misfit {
                what: format!(
                    "converting `{}` to `{}` can lose data and is not marked",
                    from.element, to.element
                ),
                span: e.span.clone(),
                help: format!("add `as {}` to say it is intended", to.element),
            }),
            _ => {}
        }
        let target = (e.to.port, e.to.index);
        if written
            .iter()
            .any(|w| *w == target || (w.0 == target.0 && (w.1.is_none() || target.1.is_none())))
        {
            out.push(Misfit {
                what: format!("`{}` is written by two entries", &e.to.port),
                span: e.to.span.clone(),
                help: "map each output element once".into(),
            });
        }
        written.push(target);
    }
    out
}

#[cfg(test)]
mod tests;
