//! The fast path of the serde codec: a port's type that mirrors its message (the same
//! fields in the same order, each of the message's own width; what check R102 proves
//! before a run) is written and read with no plan to consult, only a tape to follow.
//!
//! The tape is the message flattened once per [`Shape`](super::Shape): one op per field
//! in the order serde visits them (a nested message's fields right after it), each op
//! knowing where what it contains ends. Writing a value is then XCDR1's own rules and
//! nothing else: every primitive aligned to its size counted from after the header, a
//! string its `u32` length with the NUL counted, its bytes and the NUL, a sequence its
//! `u32` count then its elements, a fixed array its elements alone. Each serde call
//! still checks that it is what the op says (the primitive, the field's name by its
//! `&'static str`'s address once seen equal, the struct's number of fields, an array's
//! length and bound), so a value that does not fit never becomes a wrong sample.
//!
//! What the tape does not take is a [`Miss`] (one byte of nothing: no message, no path),
//! and the caller then runs the plan path (`ser.rs`, `de.rs`), which writes or reads
//! what the fast path cannot (a wrapper message as its one field, `std::time::Duration`
//! as `builtin_interfaces/msg/Duration`, a wider number read into a port) or says
//! exactly what is wrong, with the field path. A type that missed but went through the
//! plan path is remembered (the address of its `type_name`, per direction), so it takes
//! the plan path directly from then on; the memory is a hint only, never trusted for
//! the bytes.
//!
//! ferroc's `Timestamp { nanos }` as `builtin_interfaces/msg/Time` is on the tape too
//! (a header's stamp is in most messages).

mod de;
mod ser;

use super::plan::{Builtin, Elem, Plan, Slot};
use crate::def::{Arity, Primitive};
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::fmt;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Longer tapes are not made (a message that nests the same type many times over): such
/// a message takes the plan path.
const MAX_OPS: usize = 4096;

/// The value or sample is not one the tape takes; the plan path decides.
#[derive(Debug)]
pub(crate) struct Miss;

impl fmt::Display for Miss {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("not on the fast path")
    }
}

impl std::error::Error for Miss {}

impl serde::ser::Error for Miss {
    #[cold]
    fn custom<M: fmt::Display>(_: M) -> Self {
        Miss
    }
}

impl serde::de::Error for Miss {
    #[cold]
    fn custom<M: fmt::Display>(_: M) -> Self {
        Miss
    }
}

/// What a field is on the wire.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Kind {
    /// A primitive (`byte` and `char` are `uint8`, as rosidl maps them).
    Prim(Primitive),
    /// A string of at most so many bytes.
    Str(Option<u32>),
    /// A message of `len` fields (they follow); `time`: `builtin_interfaces/msg/Time`.
    Struct { len: u32, time: bool },
    /// An array (`fixed`: exactly `max` elements, no count) or a sequence (a count of at
    /// most `max`). Of a primitive (`prim`), or of what the next op is.
    Seq {
        fixed: bool,
        max: u32,
        prim: Option<Primitive>,
    },
    /// `Timestamp::nanos` as a Time's two fields (not on the tape: [`NANOS`]).
    Nanos,
}

/// One field (or the message, or an array's element) on the tape.
pub(crate) struct Op<'r> {
    pub kind: Kind,
    /// The field's name (empty for the message and for elements).
    name: &'r str,
    /// The address of the last key found equal to the name.
    seen: AtomicUsize,
    /// A message's: the address of the last list of field names (a derived
    /// `Deserialize`'s) found equal to its fields' names.
    seen_fields: AtomicUsize,
    /// The index after this op and all it contains.
    pub end: usize,
}

impl Op<'_> {
    /// Whether the port's field `key` is this field (as `Slot::named`: a `&'static str`
    /// at the same address and of the same length is the same text).
    #[inline(always)]
    pub fn named(&self, key: &'static str) -> bool {
        let at = key.as_ptr() as usize;
        if self.seen.load(Ordering::Relaxed) == at && key.len() == self.name.len() {
            return true;
        }
        self.named_slow(key)
    }

    #[cold]
    fn named_slow(&self, key: &'static str) -> bool {
        let same = key == self.name;
        if same {
            self.seen.store(key.as_ptr() as usize, Ordering::Relaxed);
        }
        same
    }
}

/// The op a `Timestamp`'s `nanos` is read and written with.
pub(crate) static NANOS: Op<'static> = Op {
    kind: Kind::Nanos,
    name: "nanos",
    seen: AtomicUsize::new(0),
    seen_fields: AtomicUsize::new(0),
    end: 0,
};

/// A message flattened for the fast path, and the types found not to fit it.
pub(crate) struct Tape<'r> {
    ops: Vec<Op<'r>>,
    /// `type_name` addresses of the last type written / read by the plan path after a
    /// miss.
    slow_write: AtomicUsize,
    slow_read: AtomicUsize,
}

impl<'r> Tape<'r> {
    /// The tape of the plan's message, unless it holds a `wstring` or is too long.
    pub fn new(plan: &Plan<'r>) -> Option<Tape<'r>> {
        let mut ops = Vec::new();
        node(plan, plan.root(), "", &mut ops)?;
        Some(Tape {
            ops,
            slow_write: AtomicUsize::new(0),
            slow_read: AtomicUsize::new(0),
        })
    }

    /// Writes `value` as a sample into `buf` (header first), or misses. Types that
    /// missed before and then were written by the plan path are not tried.
    #[inline]
    pub fn write<T: Serialize + ?Sized>(&self, value: &T, buf: &mut Vec<u8>) -> Result<(), Miss> {
        if self.slow_write.load(Ordering::Relaxed) == type_key::<T>() {
            return Err(Miss);
        }
        ser::write(&self.ops, value, buf)
    }

    /// Reads a sample as a `T`, or misses (as [`Self::write`]).
    #[inline]
    pub fn read<T: DeserializeOwned>(&self, bytes: &[u8]) -> Result<T, Miss> {
        if self.slow_read.load(Ordering::Relaxed) == type_key::<T>() {
            return Err(Miss);
        }
        de::read(&self.ops, bytes)
    }

    /// `T` missed and the plan path wrote it: it takes the plan path from now on.
    #[cold]
    pub fn written_slowly<T: ?Sized>(&self) {
        self.slow_write.store(type_key::<T>(), Ordering::Relaxed);
    }

    /// `T` missed and the plan path read it.
    #[cold]
    pub fn read_slowly<T: ?Sized>(&self) {
        self.slow_read.store(type_key::<T>(), Ordering::Relaxed);
    }
}

/// A number standing for the type `T` (the address of its name: a hint, see the
/// module documentation).
#[inline(always)]
fn type_key<T: ?Sized>() -> usize {
    std::any::type_name::<T>().as_ptr() as usize
}

/// Appends `op` and returns its index, unless the tape is full.
fn push<'r>(ops: &mut Vec<Op<'r>>, kind: Kind, name: &'r str) -> Option<usize> {
    if ops.len() >= MAX_OPS {
        return None;
    }
    ops.push(Op {
        kind,
        name,
        seen: AtomicUsize::new(0),
        seen_fields: AtomicUsize::new(0),
        end: ops.len() + 1,
    });
    Some(ops.len() - 1)
}

/// The message of the plan's node `n`, then its fields.
fn node<'r>(plan: &Plan<'r>, n: usize, name: &'r str, ops: &mut Vec<Op<'r>>) -> Option<()> {
    let node = &plan.nodes[n];
    let kind = Kind::Struct {
        len: u32::try_from(node.slots.len()).ok()?,
        time: node.builtin == Builtin::Time,
    };
    let at = push(ops, kind, name)?;
    for slot in &node.slots {
        field(plan, slot, ops)?;
    }
    ops[at].end = ops.len();
    Some(())
}

fn field<'r>(plan: &Plan<'r>, slot: &Slot<'r>, ops: &mut Vec<Op<'r>>) -> Option<()> {
    let (fixed, max) = match slot.arity {
        Arity::Single => return element(plan, &slot.elem, slot.name, ops),
        Arity::Fixed(n) => (true, n),
        Arity::Bounded(n) => (false, n),
        Arity::Unbounded => (false, u32::MAX),
    };
    let prim = match slot.elem {
        Elem::Prim(p) => Some(norm(p)),
        _ => None,
    };
    let at = push(ops, Kind::Seq { fixed, max, prim }, slot.name)?;
    if prim.is_none() {
        element(plan, &slot.elem, "", ops)?;
    }
    ops[at].end = ops.len();
    Some(())
}

fn element<'r>(plan: &Plan<'r>, elem: &Elem, name: &'r str, ops: &mut Vec<Op<'r>>) -> Option<()> {
    match *elem {
        Elem::Prim(p) => push(ops, Kind::Prim(norm(p)), name).map(drop),
        Elem::Str(bound) => push(ops, Kind::Str(bound), name).map(drop),
        Elem::WStr => None,
        Elem::Msg(n) => node(plan, n, name, ops),
    }
}

/// `byte` and `char` are `uint8`.
fn norm(p: Primitive) -> Primitive {
    match p {
        Primitive::Byte | Primitive::Char => Primitive::UInt8,
        p => p,
    }
}

/// [`Tape::write`] whatever the hint says (for tests).
pub(crate) fn write_any<T: Serialize + ?Sized>(
    tape: &Tape<'_>,
    value: &T,
    buf: &mut Vec<u8>,
) -> Result<(), Miss> {
    ser::write(&tape.ops, value, buf)
}

/// [`Tape::read`] whatever the hint says (for tests).
pub(crate) fn read_any<T: DeserializeOwned>(tape: &Tape<'_>, bytes: &[u8]) -> Result<T, Miss> {
    de::read(&tape.ops, bytes)
}
