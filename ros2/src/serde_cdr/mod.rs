//! CDR straight from a port's own value and back (issue 29): a serde `Serializer` and
//! `Deserializer` that write and read XCDR1 little endian, guided by the message
//! definition, with no intermediate form. Floats cross exactly (an infinite laser range
//! stays infinite, a NaN stays NaN).
//!
//! The definition decides what serde cannot tell: whether an array is a fixed array
//! (no length on the wire) or a sequence (a `u32` length), string and sequence bounds,
//! and where a single value sits: a port carrying one field of a message ([`Shape`]
//! with a field path: the other fields zero on the way out, skipped on the way in) or a
//! one-field wrapper (`f64` as `std_msgs/msg/Float64`). ferroc's `Timestamp` (`nanos`)
//! is `builtin_interfaces/msg/Time` and `std::time::Duration` (`secs`, `nanos`) is
//! `builtin_interfaces/msg/Duration` on the wire. A library type's fields must have the
//! message's names in its order (check R102 makes sure before a run); a value that does
//! not fit is an error naming the field, never a wrong sample.
//!
//! The rules of CDR itself (alignment, lengths, strings) are `wire.rs`'s, shared with
//! the dynamic codec ([`cdr`](crate::cdr)); decoding is as bounded against hostile
//! samples as there.

mod de;
mod ser;

use crate::cdr::{self, CdrError};
use crate::def::{Arity, BaseType, Field, FieldType, Message, Primitive, TypeName};
use crate::wire::{self, In, Out, MAX_DEPTH};
use crate::Registry;
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::fmt;

/// What a port's value is on the wire: a message type, and the field of it the port
/// carries, if only one.
#[derive(Clone)]
pub struct Shape<'r> {
    reg: &'r Registry,
    message: &'r Message,
    /// The field path: the index of each field in its message, with the message.
    path: Vec<(&'r Message, usize)>,
    /// Every nested message field's type (by address) with its definition, found once
    /// here instead of by name in the registry for every sample.
    nested: Vec<(usize, &'r Message)>,
}

/// How the codecs find nested messages: the shape's table, else the registry.
#[derive(Clone, Copy)]
pub(crate) struct Look<'r> {
    pub reg: &'r Registry,
    nested: &'r [(usize, &'r Message)],
}

impl<'r> Look<'r> {
    fn message(self, base: &'r BaseType, name: &TypeName) -> Result<&'r Message, Fail> {
        let at = base as *const BaseType as usize;
        match self.nested.iter().find(|(a, _)| *a == at) {
            Some((_, m)) => Ok(m),
            None => Ok(wire::message(self.reg, name)?),
        }
    }
}

/// The nested message fields under `m`, each once (by the address of its type).
fn nested<'r>(
    reg: &'r Registry,
    m: &'r Message,
    depth: usize,
    out: &mut Vec<(usize, &'r Message)>,
) -> Result<(), String> {
    if depth > MAX_DEPTH {
        return Err("messages are nested too deeply".into());
    }
    for f in &m.fields {
        if let BaseType::Nested(n) = &f.ty.base {
            let inner = wire::message(reg, n)?;
            out.push((&f.ty.base as *const BaseType as usize, inner));
            nested(reg, inner, depth + 1, out)?;
        }
    }
    Ok(())
}

impl fmt::Debug for Shape<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names: Vec<&str> = (self.path.iter())
            .map(|(m, i)| m.fields[*i].name.as_str())
            .collect();
        write!(f, "Shape({} {})", self.message.name, names.join("."))
    }
}

impl<'r> Shape<'r> {
    /// The message type `ty` of `reg`, all of it or with `field` (a dotted path through
    /// nested messages, `linear.x`) only that field.
    pub fn new(reg: &'r Registry, ty: &TypeName, field: Option<&str>) -> Result<Self, String> {
        let message = wire::message(reg, ty)?;
        let mut path = Vec::new();
        if let Some(field) = field {
            let mut m = message;
            let mut segments = field.split('.').peekable();
            while let Some(seg) = segments.next() {
                let i = (m.fields.iter().position(|f| f.name == seg))
                    .ok_or_else(|| format!("`{}` has no field `{seg}`", m.name))?;
                path.push((m, i));
                if segments.peek().is_none() {
                    break;
                }
                m = match (&m.fields[i].ty.base, m.fields[i].ty.arity) {
                    (BaseType::Nested(n), Arity::Single) => wire::message(reg, n)?,
                    _ => return Err(format!("field `{seg}` of `{}` has no fields", m.name)),
                };
            }
        }
        let mut table = Vec::new();
        nested(reg, message, 0, &mut table)?;
        Ok(Shape {
            reg,
            message,
            path,
            nested: table,
        })
    }

    fn look(&self) -> Look<'_> {
        Look {
            reg: self.reg,
            nested: &self.nested,
        }
    }

    /// The message type.
    pub fn message(&self) -> &'r TypeName {
        &self.message.name
    }

    /// The field the port's value is: the last of the path.
    fn leaf(&self) -> Option<&'r Field> {
        self.path.last().map(|(m, i)| &m.fields[*i])
    }

    fn names(&self) -> Vec<&'r str> {
        (self.path.iter())
            .map(|(m, i)| m.fields[*i].name.as_str())
            .collect()
    }
}

/// Writes `value` as a CDR sample of `shape` into `buf` (replacing what it held, its
/// capacity kept).
pub fn to_cdr<T: Serialize + ?Sized>(
    shape: &Shape<'_>,
    value: &T,
    buf: &mut Vec<u8>,
) -> Result<(), CdrError> {
    to_cdr_in(shape, value, buf)
}

/// [`to_cdr`] with the shape's borrow and its registry's as one lifetime.
fn to_cdr_in<'s, T: Serialize + ?Sized>(
    shape: &'s Shape<'s>,
    value: &T,
    buf: &mut Vec<u8>,
) -> Result<(), CdrError> {
    let mut w = ser::W {
        reg: shape.look(),
        out: Out::new(std::mem::take(buf)),
        path: Vec::new(),
    };
    let done = write(shape, value, &mut w);
    let path = std::mem::take(&mut w.path);
    *buf = w.out.buf;
    done.map_err(|e| cdr::error(&path, e.0))
}

/// `value` as a new CDR sample of `shape`.
pub fn encode<T: Serialize + ?Sized>(shape: &Shape<'_>, value: &T) -> Result<Vec<u8>, CdrError> {
    let mut buf = Vec::new();
    to_cdr(shape, value, &mut buf)?;
    Ok(buf)
}

fn write<'r, T: Serialize + ?Sized>(
    shape: &Shape<'r>,
    value: &T,
    w: &mut ser::W<'r>,
) -> Result<(), Fail> {
    let Some(leaf) = shape.leaf() else {
        return value.serialize(ser::Ser::new(w, Expect::Message(shape.message)));
    };
    for (m, i) in &shape.path {
        for f in &m.fields[..*i] {
            w.out.zero_field(w.reg.reg, &f.ty, 0).map_err(Fail)?;
        }
    }
    w.path = shape.names();
    value.serialize(ser::Ser::new(w, Expect::Field(&leaf.ty)))?;
    w.path.clear();
    for (m, i) in shape.path.iter().rev() {
        for f in &m.fields[*i + 1..] {
            w.out.zero_field(w.reg.reg, &f.ty, 0).map_err(Fail)?;
        }
    }
    Ok(())
}

/// Reads a CDR sample of `shape` as a value of `T`.
pub fn from_cdr<T: DeserializeOwned>(shape: &Shape<'_>, bytes: &[u8]) -> Result<T, CdrError> {
    from_cdr_in(shape, bytes)
}

/// [`from_cdr`] with the shape's borrow and its registry's as one lifetime.
fn from_cdr_in<'s, T: DeserializeOwned>(shape: &'s Shape<'s>, bytes: &[u8]) -> Result<T, CdrError> {
    let input = In::new(bytes).map_err(|e| cdr::error::<&str>(&[], e))?;
    let mut r = de::R {
        reg: shape.look(),
        input,
        path: Vec::new(),
    };
    let value = read(shape, &mut r).map_err(|e| cdr::error(&r.path, e.0))?;
    (r.input.finish(&shape.message.name)).map_err(|e| cdr::error::<&str>(&[], e))?;
    Ok(value)
}

fn read<'r, T: DeserializeOwned>(shape: &Shape<'r>, r: &mut de::R<'r, '_>) -> Result<T, Fail> {
    let Some(leaf) = shape.leaf() else {
        return T::deserialize(de::De::new(r, Expect::Message(shape.message)));
    };
    for (m, i) in &shape.path {
        for f in &m.fields[..*i] {
            r.skip(f)?;
        }
    }
    r.path = shape.names();
    let value = T::deserialize(de::De::new(r, Expect::Field(&leaf.ty)))?;
    r.path.clear();
    for (m, i) in shape.path.iter().rev() {
        for f in &m.fields[*i + 1..] {
            r.skip(f)?;
        }
    }
    Ok(value)
}

/// What the definition expects next.
#[derive(Clone, Copy)]
enum Expect<'r> {
    Message(&'r Message),
    /// A field: one value or an array of them.
    Field(&'r FieldType),
    /// One element.
    Base(&'r BaseType),
    /// `builtin_interfaces/msg/Time` from `Timestamp::nanos`.
    TimeNanos,
    /// `builtin_interfaces/msg/Duration::sec` (int32) from `Duration::secs` (u64).
    DurationSecs,
}

/// `uint32`, for `Duration::nanos`.
static UINT32: BaseType = BaseType::Primitive(Primitive::UInt32);

impl<'r> Expect<'r> {
    /// One value is a base type; a nested message is its definition.
    #[inline]
    fn resolve(self, reg: Look<'r>) -> Result<Expect<'r>, Fail> {
        Ok(match self {
            Expect::Field(FieldType {
                base,
                arity: Arity::Single,
            }) => Expect::Base(base).resolve(reg)?,
            Expect::Base(base @ BaseType::Nested(n)) => Expect::Message(reg.message(base, n)?),
            e => e,
        })
    }

    /// [`Self::resolve`], and a message of one field (a wrapper such as
    /// `std_msgs/msg/Float64`) is that field: where a single value or a plain array is
    /// found.
    #[inline]
    fn unwrap(self, reg: Look<'r>) -> Result<Expect<'r>, Fail> {
        let mut e = self.resolve(reg)?;
        for _ in 0..MAX_DEPTH {
            match e {
                Expect::Message(Message { fields, .. }) if fields.len() == 1 => {
                    e = Expect::Field(&fields[0].ty).resolve(reg)?;
                }
                e => return Ok(e),
            }
        }
        Err(Fail("messages are nested too deeply".into()))
    }

    fn describe(self) -> String {
        match self {
            Expect::Message(m) => format!("a `{}` message", m.name),
            Expect::Field(t) => match t.arity {
                Arity::Single => Expect::Base(&t.base).describe(),
                Arity::Fixed(n) => format!("an array of {n}"),
                Arity::Bounded(n) => format!("a sequence of at most {n}"),
                Arity::Unbounded => "a sequence".into(),
            },
            Expect::Base(BaseType::Primitive(p)) => p.msg_name().into(),
            Expect::Base(BaseType::String { .. }) => "a string".into(),
            Expect::Base(BaseType::WString { .. }) => "a wstring (not supported)".into(),
            Expect::Base(BaseType::Nested(n)) => format!("a `{n}` message"),
            Expect::TimeNanos => "`Timestamp::nanos`".into(),
            Expect::DurationSecs => "`Duration::secs`".into(),
        }
    }
}

/// Whether `m` is `builtin_interfaces/msg/NAME`.
fn builtin(m: &Message, name: &str) -> bool {
    m.name.package == "builtin_interfaces" && m.name.name == name
}

/// `byte` and `char` are `uint8` (rosidl's mapping).
fn same(ours: Primitive, theirs: Primitive) -> bool {
    let norm = |p| match p {
        Primitive::Byte | Primitive::Char => Primitive::UInt8,
        p => p,
    };
    norm(ours) == norm(theirs)
}

/// Why a value does not fit its message (the codecs add the field path).
#[derive(Debug)]
pub(crate) struct Fail(pub String);

impl fmt::Display for Fail {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Fail {}

impl serde::ser::Error for Fail {
    fn custom<M: fmt::Display>(msg: M) -> Self {
        Fail(msg.to_string())
    }
}

impl serde::de::Error for Fail {
    fn custom<M: fmt::Display>(msg: M) -> Self {
        Fail(msg.to_string())
    }
}

impl From<String> for Fail {
    fn from(s: String) -> Self {
        Fail(s)
    }
}

impl From<&str> for Fail {
    fn from(s: &str) -> Self {
        Fail(s.to_string())
    }
}

impl From<CdrError> for Fail {
    fn from(e: CdrError) -> Self {
        Fail(e.to_string())
    }
}
