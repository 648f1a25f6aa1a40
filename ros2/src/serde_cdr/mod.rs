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
//!
//! Speed (the `cdr` benchmark, issue 29's target: no slower than 1.2 × postcard): a
//! value takes the fastest of three paths that fits it, all writing the same bytes.
//! - The plan path (`ser.rs`, `de.rs`): the definition compiled once per shape
//!   (`plan.rs`: nested types resolved, field names compared once per port type), an
//!   array or sequence of a primitive aligned and sized once, its elements then written
//!   back to back and read from its bytes taken whole (`prim.rs`); errors name the field.
//!   It takes every value, and says what is wrong.
//! - The tape (`fast/`): for a whole message, the definition flattened into one op per
//!   field in serde's order, each with the padding before it where the tape knows it;
//!   each serde call checked against its op (primitive, field name by address, number
//!   of fields, lengths). Anything else is a miss, and the plan path runs instead; a type
//!   that missed and then went through the plan path goes there directly from then on.
//! - The trusted writer (`fast/trusted.rs`): a type that went through the tape once and
//!   whose message's layout depends on nothing but sequence lengths and strings is
//!   written by XCDR1's rules alone, the tape consulted only for its sequences; the
//!   number of fields and of sequences visited is still checked in every sample (a miss
//!   goes back to the tape). An array of a primitive is made room for once and its
//!   elements written into it (`fast/packed.rs`, the tape's writer too).
//! - The trusted reader (`fast/trusted_read.rs`): its reading side, for the same
//!   messages, once a type has read a sample along the tape: each primitive read
//!   aligned with one bounds check, the tape consulted only for sequences; every length,
//!   bound, NUL, UTF-8 and `bool` still checked against the bytes, and the number of
//!   fields and sequences read (a miss reads the sample along the tape).
//!
//! Nothing is allocated per sample but the value's own strings and vectors: an error's
//! field path is built only when there is an error.

mod de;
mod fast;
mod plan;
mod prim;
mod ser;

use crate::cdr::CdrError;
use crate::def::{Arity, Primitive, TypeName};
use crate::wire::{Out, MAX_DEPTH};
use crate::Registry;
use plan::{Elem, Node, Plan, Slot};
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::fmt;
use std::sync::Arc;

/// What a port's value is on the wire: a message type, and the field of it the port
/// carries, if only one.
#[derive(Clone)]
pub struct Shape<'r> {
    /// The message and every message it nests, compiled (shared by the clones).
    plan: Arc<Plan<'r>>,
    /// The field path: the node of each message on the way and the field's index in it.
    path: Vec<(usize, usize)>,
    /// The message flattened for the fast path (a whole message only, see `fast/`).
    fast: Option<Arc<fast::Tape<'r>>>,
}

impl fmt::Debug for Shape<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Shape({} {})", self.message(), self.names().join("."))
    }
}

impl<'r> Shape<'r> {
    /// The message type `ty` of `reg`, all of it or with `field` (a dotted path through
    /// nested messages, `linear.x`) only that field.
    pub fn new(reg: &'r Registry, ty: &TypeName, field: Option<&str>) -> Result<Self, String> {
        let plan = Plan::new(reg, crate::wire::message(reg, ty)?)?;
        let mut path = Vec::new();
        if let Some(field) = field {
            let mut node = plan.root();
            let mut segments = field.split('.').peekable();
            while let Some(seg) = segments.next() {
                let n = &plan.nodes[node];
                let i = (n.slots.iter().position(|s| s.field.name == seg))
                    .ok_or_else(|| format!("`{}` has no field `{seg}`", n.message.name))?;
                path.push((node, i));
                if segments.peek().is_none() {
                    break;
                }
                node = match (n.slots[i].elem, n.slots[i].arity) {
                    (Elem::Msg(inner), Arity::Single) => inner,
                    _ => {
                        return Err(format!(
                            "field `{seg}` of `{}` has no fields",
                            n.message.name
                        ))
                    }
                };
            }
        }
        let fast = match path.is_empty() {
            true => fast::Tape::new(&plan).map(Arc::new),
            false => None,
        };
        Ok(Shape {
            plan: Arc::new(plan),
            path,
            fast,
        })
    }

    /// The message type.
    pub fn message(&self) -> &'r TypeName {
        &self.plan.nodes[self.plan.root()].message.name
    }

    /// The field the port's value is: the last of the path.
    fn leaf(&self) -> Option<&Slot<'r>> {
        (self.path.last()).map(|&(n, i)| &self.plan.nodes[n].slots[i])
    }

    fn names(&self) -> Vec<&str> {
        (self.path.iter())
            .map(|&(n, i)| self.plan.nodes[n].slots[i].field.name.as_str())
            .collect()
    }

    /// `fail` inside the path's first `depth` fields.
    #[cold]
    fn within(&self, depth: usize, mut fail: Fail) -> Fail {
        for name in self.names()[..depth].iter().rev() {
            fail = fail.within(name);
        }
        fail
    }
}

/// Writes `value` as a CDR sample of `shape` into `buf` (replacing what it held, its
/// capacity kept).
#[inline]
pub fn to_cdr<T: Serialize + ?Sized>(
    shape: &Shape<'_>,
    value: &T,
    buf: &mut Vec<u8>,
) -> Result<(), CdrError> {
    let Some(tape) = &shape.fast else {
        return to_cdr_in(shape, value, buf);
    };
    if tape.write(value, buf).is_ok() {
        return Ok(());
    }
    let planned = to_cdr_in(shape, value, buf);
    if planned.is_ok() {
        tape.written_slowly::<T>();
    }
    planned
}

/// [`to_cdr`] by the plan path alone (for tests and benchmarks: the fast path must
/// write the same bytes).
#[doc(hidden)]
pub fn to_cdr_planned<T: Serialize + ?Sized>(
    shape: &Shape<'_>,
    value: &T,
    buf: &mut Vec<u8>,
) -> Result<(), CdrError> {
    to_cdr_in(shape, value, buf)
}

/// How [`to_cdr`] writes values of `T` now: `"trusted"` (a type that mirrors the
/// message, found so in a checked sample), `"tape"` (the fast path, checked) or `"plan"`
/// (for tests and benchmarks; see `fast/`).
#[doc(hidden)]
pub fn write_path<T: Serialize + ?Sized>(shape: &Shape<'_>) -> &'static str {
    (shape.fast.as_ref()).map_or("plan", |tape| tape.write_path::<T>())
}

/// [`to_cdr`] by the fast path alone: `false` where it misses (for tests: which types
/// it takes).
#[doc(hidden)]
pub fn to_cdr_fast<T: Serialize + ?Sized>(shape: &Shape<'_>, value: &T, buf: &mut Vec<u8>) -> bool {
    (shape.fast.as_ref()).is_some_and(|tape| fast::write_any(tape, value, buf).is_ok())
}

/// [`to_cdr`] with the shape's borrow and its registry's as one lifetime.
fn to_cdr_in<'s, T: Serialize + ?Sized>(
    shape: &'s Shape<'s>,
    value: &T,
    buf: &mut Vec<u8>,
) -> Result<(), CdrError> {
    let mut w = ser::W {
        plan: &shape.plan,
        out: Out::new(std::mem::take(buf)),
    };
    let done = write(shape, value, &mut w);
    *buf = w.out.buf;
    done.map_err(Fail::into_error)
}

/// `value` as a new CDR sample of `shape`.
pub fn encode<T: Serialize + ?Sized>(shape: &Shape<'_>, value: &T) -> Result<Vec<u8>, CdrError> {
    let mut buf = Vec::new();
    to_cdr(shape, value, &mut buf)?;
    Ok(buf)
}

fn write<'p, T: Serialize + ?Sized>(
    shape: &'p Shape<'p>,
    value: &T,
    w: &mut ser::W<'p>,
) -> Result<(), Fail> {
    let plan = &*shape.plan;
    let Some(leaf) = shape.leaf() else {
        return value.serialize(ser::Ser::new(w, Expect::Message(&plan.nodes[plan.root()])));
    };
    let fields = |&(n, _): &(usize, usize)| &plan.nodes[n].message.fields;
    for (depth, at) in shape.path.iter().enumerate() {
        for f in &fields(at)[..at.1] {
            let zero = w.out.zero_field(plan.reg, &f.ty, 0);
            zero.map_err(|e| shape.within(depth, Fail::new(e)))?;
        }
    }
    (value.serialize(ser::Ser::new(w, Expect::Field(leaf))))
        .map_err(|e| shape.within(shape.path.len(), e))?;
    for (depth, at) in shape.path.iter().enumerate().rev() {
        for f in &fields(at)[at.1 + 1..] {
            let zero = w.out.zero_field(plan.reg, &f.ty, 0);
            zero.map_err(|e| shape.within(depth, Fail::new(e)))?;
        }
    }
    Ok(())
}

/// Reads a CDR sample of `shape` as a value of `T`.
#[inline]
pub fn from_cdr<T: DeserializeOwned>(shape: &Shape<'_>, bytes: &[u8]) -> Result<T, CdrError> {
    let Some(tape) = &shape.fast else {
        return from_cdr_in(shape, bytes);
    };
    if let Ok(value) = tape.read(bytes) {
        return Ok(value);
    }
    let planned = from_cdr_in(shape, bytes);
    if planned.is_ok() {
        tape.read_slowly::<T>();
    }
    planned
}

/// [`from_cdr`] by the plan path alone (for tests and benchmarks).
#[doc(hidden)]
pub fn from_cdr_planned<T: DeserializeOwned>(
    shape: &Shape<'_>,
    bytes: &[u8],
) -> Result<T, CdrError> {
    from_cdr_in(shape, bytes)
}

/// [`from_cdr`] by the fast path alone: `None` where it misses (for tests).
#[doc(hidden)]
pub fn from_cdr_fast<T: DeserializeOwned>(shape: &Shape<'_>, bytes: &[u8]) -> Option<T> {
    (shape.fast.as_ref()).and_then(|tape| fast::read_any(tape, bytes).ok())
}

/// How [`from_cdr`] reads samples as `T` now: `"trusted"` (a type that mirrors the
/// message, found so in a sample read along the tape), `"tape"` or `"plan"` (for tests).
#[doc(hidden)]
pub fn read_path<T: DeserializeOwned>(shape: &Shape<'_>) -> &'static str {
    (shape.fast.as_ref()).map_or("plan", |tape| tape.read_path::<T>())
}

/// The trusted reader alone (`fast/trusted_read.rs`), as if `T` had been found to
/// mirror the message: `None` where it misses (for tests).
#[doc(hidden)]
pub fn from_cdr_trusted<T: DeserializeOwned>(shape: &Shape<'_>, bytes: &[u8]) -> Option<T> {
    (shape.fast.as_ref()).and_then(|tape| fast::read_trusted(tape, bytes).ok())
}

/// [`from_cdr`] with the shape's borrow and its registry's as one lifetime.
fn from_cdr_in<'s, T: DeserializeOwned>(shape: &'s Shape<'s>, bytes: &[u8]) -> Result<T, CdrError> {
    let input = crate::wire::In::new(bytes).map_err(|e| Fail::new(e).into_error())?;
    let mut r = de::R {
        plan: &shape.plan,
        input,
    };
    let value = read(shape, &mut r).map_err(Fail::into_error)?;
    (r.input.finish(shape.message())).map_err(|e| Fail::new(e).into_error())?;
    Ok(value)
}

fn read<'p, T: DeserializeOwned>(shape: &'p Shape<'p>, r: &mut de::R<'p, '_>) -> Result<T, Fail> {
    let plan = &*shape.plan;
    let Some(leaf) = shape.leaf() else {
        return T::deserialize(de::De::new(r, Expect::Message(&plan.nodes[plan.root()])));
    };
    let fields = |&(n, _): &(usize, usize)| &plan.nodes[n].message.fields;
    for (depth, at) in shape.path.iter().enumerate() {
        for f in &fields(at)[..at.1] {
            r.skip(f).map_err(|e| shape.within(depth, e))?;
        }
    }
    let value = (T::deserialize(de::De::new(r, Expect::Field(leaf))))
        .map_err(|e| shape.within(shape.path.len(), e))?;
    for (depth, at) in shape.path.iter().enumerate().rev() {
        for f in &fields(at)[at.1 + 1..] {
            r.skip(f).map_err(|e| shape.within(depth, e))?;
        }
    }
    Ok(value)
}

/// What the definition expects next.
#[derive(Clone, Copy)]
enum Expect<'p> {
    Message(&'p Node<'p>),
    /// A field: one value or an array of them.
    Field(&'p Slot<'p>),
    /// One element.
    Elem(&'p Elem),
    /// `builtin_interfaces/msg/Time` from `Timestamp::nanos`.
    TimeNanos,
    /// `builtin_interfaces/msg/Duration::sec` (int32) from `Duration::secs` (u64).
    DurationSecs,
}

impl<'p> Expect<'p> {
    /// A field of a message: one value is its element.
    #[inline]
    fn of(slot: &'p Slot<'p>) -> Expect<'p> {
        match slot.arity {
            Arity::Single => Expect::Elem(&slot.elem),
            _ => Expect::Field(slot),
        }
    }

    /// One value is an element; a nested message is its node.
    #[inline]
    fn resolve(self, plan: &'p Plan<'p>) -> Expect<'p> {
        let e = match self {
            Expect::Field(slot) if slot.arity == Arity::Single => Expect::Elem(&slot.elem),
            e => e,
        };
        match e {
            Expect::Elem(&Elem::Msg(n)) => Expect::Message(&plan.nodes[n]),
            e => e,
        }
    }

    /// [`Self::resolve`], and a message of one field (a wrapper such as
    /// `std_msgs/msg/Float64`) is that field: where a single value or a plain array is
    /// found.
    #[inline]
    fn unwrap(self, plan: &'p Plan<'p>) -> Result<Expect<'p>, Fail> {
        match self {
            Expect::Field(slot) if slot.arity != Arity::Single => Ok(self),
            Expect::Elem(Elem::Prim(_) | Elem::Str(_)) => Ok(self),
            _ => self.unwrap_message(plan),
        }
    }

    fn unwrap_message(self, plan: &'p Plan<'p>) -> Result<Expect<'p>, Fail> {
        let mut e = self.resolve(plan);
        for _ in 0..MAX_DEPTH {
            match e {
                Expect::Message(Node { slots, .. }) if slots.len() == 1 => {
                    e = Expect::Field(&slots[0]).resolve(plan);
                }
                e => return Ok(e),
            }
        }
        Err(Fail::new("messages are nested too deeply"))
    }

    #[cold]
    fn describe(self, plan: &Plan<'_>) -> String {
        match self {
            Expect::Message(n) => format!("a `{}` message", n.message.name),
            Expect::Field(s) => match s.arity {
                Arity::Single => Expect::Elem(&s.elem).describe(plan),
                Arity::Fixed(n) => format!("an array of {n}"),
                Arity::Bounded(n) => format!("a sequence of at most {n}"),
                Arity::Unbounded => "a sequence".into(),
            },
            Expect::Elem(Elem::Prim(p)) => p.msg_name().into(),
            Expect::Elem(Elem::Str(_)) => "a string".into(),
            Expect::Elem(Elem::WStr) => "a wstring (not supported)".into(),
            Expect::Elem(&Elem::Msg(n)) => format!("a `{}` message", plan.nodes[n].message.name),
            Expect::TimeNanos => "`Timestamp::nanos`".into(),
            Expect::DurationSecs => "`Duration::secs`".into(),
        }
    }
}

/// `Duration::nanos`: `builtin_interfaces/msg/Duration::nanosec`.
static UINT32: Elem = Elem::Prim(Primitive::UInt32);

/// `byte` and `char` are `uint8` (rosidl's mapping).
#[inline]
fn same(ours: Primitive, theirs: Primitive) -> bool {
    let norm = |p| match p {
        Primitive::Byte | Primitive::Char => Primitive::UInt8,
        p => p,
    };
    norm(ours) == norm(theirs)
}

/// Why a value does not fit its message, and in which field (boxed: the codecs'
/// results stay one word wide).
#[derive(Debug)]
pub(crate) struct Fail(Box<Failure>);

#[derive(Debug)]
struct Failure {
    message: String,
    /// The field path (`ranges[3]`, `pose.pose.position.x`), built as the error leaves
    /// each field.
    path: String,
}

impl Fail {
    #[cold]
    pub fn new(message: impl Into<String>) -> Fail {
        Fail(Box::new(Failure {
            message: message.into(),
            path: String::new(),
        }))
    }

    /// The failure inside the field `name` (or `[i]`, an element).
    #[cold]
    pub fn within(mut self, name: &str) -> Fail {
        let path = &mut self.0.path;
        if !path.is_empty() && !path.starts_with('[') {
            path.insert(0, '.');
        }
        path.insert_str(0, name);
        self
    }

    /// The failure inside element `index` of an array.
    #[cold]
    pub fn at(self, index: usize) -> Fail {
        self.within(&format!("[{index}]"))
    }

    fn into_error(self) -> CdrError {
        let Failure { message, path } = *self.0;
        CdrError { path, message }
    }
}

impl fmt::Display for Fail {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0.message)
    }
}

impl std::error::Error for Fail {}

impl serde::ser::Error for Fail {
    #[cold]
    fn custom<M: fmt::Display>(msg: M) -> Self {
        Fail::new(msg.to_string())
    }
}

impl serde::de::Error for Fail {
    #[cold]
    fn custom<M: fmt::Display>(msg: M) -> Self {
        Fail::new(msg.to_string())
    }
}

impl From<String> for Fail {
    #[cold]
    fn from(s: String) -> Self {
        Fail::new(s)
    }
}

impl From<&str> for Fail {
    #[cold]
    fn from(s: &str) -> Self {
        Fail::new(s)
    }
}

impl From<CdrError> for Fail {
    #[cold]
    fn from(e: CdrError) -> Self {
        Fail(Box::new(Failure {
            message: e.message,
            path: e.path,
        }))
    }
}
