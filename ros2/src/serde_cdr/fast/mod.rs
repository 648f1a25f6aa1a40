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
//!
//! The padding before each primitive (and each length) is worked out while the tape is
//! made, from what is known of the offset there (everything, up to the first string or
//! sequence; to a multiple of the last alignment after that), so most fields are
//! written and read with no alignment computed at all.
//!
//! A type that went through the tape without a miss may be trusted from then on
//! (`trusted.rs`): written with no tape but for its sequences, where the message's
//! layout allows it. The type is known by the address of its trusted writer
//! ([`trust_key`]); a trusted sample that misses is written through the tape again.
//! Reading likewise (`trusted_read.rs`): a type that read a sample along the tape (every
//! Time a `Timestamp`, no `Timestamp` elsewhere) is read from then on with no tape but
//! for its sequences ([`read_key`]); a sample it misses is read along the tape.

/// The deserializer methods both fast readers share (`de.rs` along the tape,
/// `trusted_read.rs` without it): what a mirroring type never asks for is a miss, and
/// the forms serde may pick for one thing (`String` or `str`, a byte buffer or bytes; a
/// sequence, tuple or tuple struct) go one way. Each reader has its own
/// `deserialize_str`, `deserialize_bytes` and `elements(len, visitor)`.
macro_rules! de_shared {
    ($d:lifetime) => {
        de_shared!(@refuse $d deserialize_any deserialize_char
            deserialize_option deserialize_unit deserialize_map deserialize_identifier
            deserialize_ignored_any);
        #[inline]
        fn deserialize_string<V: Visitor<$d>>(self, v: V) -> Result<V::Value, Miss> {
            self.deserialize_str(v)
        }
        fn deserialize_byte_buf<V: Visitor<$d>>(self, v: V) -> Result<V::Value, Miss> {
            self.deserialize_bytes(v)
        }
        fn deserialize_unit_struct<V: Visitor<$d>>(
            self,
            _: &'static str,
            _: V,
        ) -> Result<V::Value, Miss> {
            Err(Miss)
        }
        #[inline(always)]
        fn deserialize_newtype_struct<V: Visitor<$d>>(
            self,
            _: &'static str,
            v: V,
        ) -> Result<V::Value, Miss> {
            v.visit_newtype_struct(self)
        }
        #[inline]
        fn deserialize_seq<V: Visitor<$d>>(self, v: V) -> Result<V::Value, Miss> {
            self.elements(None, v)
        }
        #[inline]
        fn deserialize_tuple<V: Visitor<$d>>(self, len: usize, v: V) -> Result<V::Value, Miss> {
            self.elements(Some(len), v)
        }
        #[inline]
        fn deserialize_tuple_struct<V: Visitor<$d>>(
            self,
            _: &'static str,
            len: usize,
            v: V,
        ) -> Result<V::Value, Miss> {
            self.elements(Some(len), v)
        }
    };
    (@refuse $d:lifetime $($name:ident)*) => {
        $(fn $name<V: Visitor<$d>>(self, _: V) -> Result<V::Value, Miss> {
            Err(Miss)
        })*
    };
}

/// The serializer methods the fast writers refuse (a miss): one list for the tape's
/// writer (`ser.rs`) and the trusted one (`trusted.rs`), each with its own `No`
/// (`Impossible<(), Miss>`) for the compounds.
macro_rules! miss {
    (@ char) => { fn serialize_char(self, _: char) -> Result<(), Miss> { Err(Miss) } };
    (@ str) => { fn serialize_str(self, _: &str) -> Result<(), Miss> { Err(Miss) } };
    (@ bytes) => { fn serialize_bytes(self, _: &[u8]) -> Result<(), Miss> { Err(Miss) } };
    (@ none) => { fn serialize_none(self) -> Result<(), Miss> { Err(Miss) } };
    (@ some) => {
        fn serialize_some<T: Serialize + ?Sized>(self, _: &T) -> Result<(), Miss> { Err(Miss) }
    };
    (@ unit) => {
        fn serialize_unit(self) -> Result<(), Miss> { Err(Miss) }
        fn serialize_unit_struct(self, _: &'static str) -> Result<(), Miss> { Err(Miss) }
    };
    (@ variants) => {
        fn serialize_unit_variant(self, _: &'static str, _: u32, _: &'static str)
            -> Result<(), Miss> { Err(Miss) }
        fn serialize_newtype_variant<T: Serialize + ?Sized>(
            self, _: &'static str, _: u32, _: &'static str, _: &T,
        ) -> Result<(), Miss> { Err(Miss) }
        fn serialize_tuple_variant(self, _: &'static str, _: u32, _: &'static str, _: usize)
            -> Result<No, Miss> { Err(Miss) }
        fn serialize_struct_variant(self, _: &'static str, _: u32, _: &'static str, _: usize)
            -> Result<No, Miss> { Err(Miss) }
    };
    (@ map) => {
        fn serialize_map(self, _: Option<usize>) -> Result<No, Miss> { Err(Miss) }
    };
    ($($what:ident)*) => { $(miss!(@ $what);)* };
}

/// A sequence, a tuple and a tuple struct written alike: each element by the writer's
/// `Seq::element`, the end by its `Seq::finish` (both writers).
macro_rules! seq_impls {
    ($($tr:ident $f:ident),*) => {
        $(impl ser::$tr for Seq<'_, '_> {
            type Ok = ();
            type Error = Miss;
            #[inline(always)]
            fn $f<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Miss> {
                self.element(value)
            }
            #[inline(always)]
            fn end(self) -> Result<(), Miss> {
                self.finish()
            }
        })*
    };
}

mod de;
mod packed;
mod read;
mod ser;
mod trusted;
mod trusted_read;

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

/// What a field is on the wire (one byte: the primitive's own, or one of the others).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Kind {
    /// A primitive (`byte` and `char` are `uint8`, as rosidl maps them).
    Prim(Primitive),
    /// A string of at most [`Op::n`] bytes.
    Str,
    /// A message of [`Op::n`] fields (they follow).
    Struct,
    /// An array ([`Op::fixed`]: exactly [`Op::n`] elements, no count) or a sequence (a
    /// count of at most [`Op::n`]), of [`Op::elem`] or of what the next op is.
    Seq,
    /// `Timestamp::nanos` as a Time's two fields (not on the tape: [`NANOS`]).
    Nanos,
}

/// The padding before a value is not known from the tape (it follows a string or a
/// sequence): it is computed from the offset.
pub(crate) const DYNAMIC: u8 = u8::MAX;

/// One field (or the message, or an array's element) on the tape.
pub(crate) struct Op<'r> {
    pub kind: Kind,
    /// The padding before the primitive, or the length of a string or sequence: `0..8`
    /// known from the tape, or [`DYNAMIC`].
    pub pad: u8,
    /// The padding before the first element of an array of a primitive.
    pub pad_elem: u8,
    /// An array's element, if a primitive (written and read packed).
    pub elem: Option<Primitive>,
    /// An array, not a sequence.
    pub fixed: bool,
    /// A message that is `builtin_interfaces/msg/Time`.
    pub time: bool,
    /// A string's bound (`u32::MAX`: none), a sequence's (`u32::MAX`: none) or an
    /// array's length, a message's number of fields.
    pub n: u32,
    /// The index after this op and all it contains.
    pub end: usize,
    /// The address of the last key found equal to the name.
    seen: AtomicUsize,
    /// A message's: the address of the last list of field names (a derived
    /// `Deserialize`'s) found equal to its fields' names.
    seen_fields: AtomicUsize,
    /// The field's name (empty for the message and for elements).
    name: &'r str,
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
    pad: DYNAMIC,
    pad_elem: DYNAMIC,
    elem: None,
    fixed: false,
    time: false,
    n: 0,
    end: 0,
    seen: AtomicUsize::new(0),
    seen_fields: AtomicUsize::new(0),
    name: "nanos",
};

/// A message flattened for the fast path, and the types found not to fit it.
pub(crate) struct Tape<'r> {
    ops: Vec<Op<'r>>,
    /// The message's layout if it qualifies for the trusted writer (`trusted.rs`), and
    /// the type found to mirror it ([`trust_key`]).
    layout: Option<trusted::Layout>,
    trusted: AtomicUsize,
    /// The type found to mirror the message when read ([`read_key`]).
    trusted_read: AtomicUsize,
    /// `type_name` addresses of the last type written / read by the plan path after a
    /// miss.
    slow_write: AtomicUsize,
    slow_read: AtomicUsize,
}

impl<'r> Tape<'r> {
    /// The tape of the plan's message, unless it holds a `wstring` or is too long.
    pub fn new(plan: &Plan<'r>) -> Option<Tape<'r>> {
        let mut make = Make {
            plan,
            ops: Vec::new(),
            offset: 0,
            modulus: 8,
        };
        make.node(plan.root(), "")?;
        Some(Tape {
            layout: trusted::Layout::new(&make.ops),
            trusted: AtomicUsize::new(0),
            trusted_read: AtomicUsize::new(0),
            ops: make.ops,
            slow_write: AtomicUsize::new(0),
            slow_read: AtomicUsize::new(0),
        })
    }

    /// Writes `value` as a sample into `buf` (header first), or misses. Types that
    /// missed before and then were written by the plan path are not tried.
    #[inline]
    pub fn write<T: Serialize + ?Sized>(&self, value: &T, buf: &mut Vec<u8>) -> Result<(), Miss> {
        if let Some(layout) = &self.layout {
            if self.trusted.load(Ordering::Relaxed) == trust_key::<T>() {
                if trusted::write(layout, value, buf).is_ok() {
                    return Ok(());
                }
                // Not as the checked sample was: checked again.
                self.trusted.store(0, Ordering::Relaxed);
            }
        }
        if self.slow_write.load(Ordering::Relaxed) == type_key::<T>() {
            return Err(Miss);
        }
        if ser::write(&self.ops, value, buf)? && self.layout.is_some() {
            self.trusted.store(trust_key::<T>(), Ordering::Relaxed);
        }
        Ok(())
    }

    /// Reads a sample as a `T`, or misses (as [`Self::write`]).
    #[inline]
    pub fn read<T: DeserializeOwned>(&self, bytes: &[u8]) -> Result<T, Miss> {
        if let Some(layout) = &self.layout {
            if self.trusted_read.load(Ordering::Relaxed) == read_key::<T>() {
                if let Ok(value) = trusted_read::read(layout, bytes) {
                    return Ok(value);
                }
                // A bad sample, or a type not as its checked sample was: along the
                // tape, which trusts it again if it reads it.
                self.trusted_read.store(0, Ordering::Relaxed);
            }
        }
        if self.slow_read.load(Ordering::Relaxed) == type_key::<T>() {
            return Err(Miss);
        }
        let (value, trustable) = de::read(&self.ops, bytes)?;
        if trustable && self.layout.is_some() {
            self.trusted_read.store(read_key::<T>(), Ordering::Relaxed);
        }
        Ok(value)
    }

    /// How values of `T` are written now: `"trusted"`, `"tape"` or `"plan"` (for tests).
    pub fn write_path<T: Serialize + ?Sized>(&self) -> &'static str {
        if self.layout.is_some() && self.trusted.load(Ordering::Relaxed) == trust_key::<T>() {
            "trusted"
        } else if self.slow_write.load(Ordering::Relaxed) == type_key::<T>() {
            "plan"
        } else {
            "tape"
        }
    }

    /// How samples are read as `T` now: `"trusted"`, `"tape"` or `"plan"` (for tests).
    pub fn read_path<T: DeserializeOwned>(&self) -> &'static str {
        if self.layout.is_some() && self.trusted_read.load(Ordering::Relaxed) == read_key::<T>() {
            "trusted"
        } else if self.slow_read.load(Ordering::Relaxed) == type_key::<T>() {
            "plan"
        } else {
            "tape"
        }
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

/// A number standing for the type `T` that only `T` has (as far as serde can tell): the
/// address of the trusted writer made for `T`. Two types could share it only if that
/// writer's code were the same for both (identical code folded by the linker), calling
/// the same `serialize`: then they visit the same fields the same way.
#[inline(always)]
fn trust_key<T: Serialize + ?Sized>() -> usize {
    let writer: fn(&trusted::Layout, &T, &mut Vec<u8>) -> Result<(), Miss> = trusted::write::<T>;
    writer as usize
}

/// [`trust_key`] for reading: the address of the trusted reader made for `T`.
#[inline(always)]
fn read_key<T: DeserializeOwned>() -> usize {
    let reader: fn(&trusted::Layout, &[u8]) -> Result<T, Miss> = trusted_read::read::<T>;
    reader as usize
}

/// The tape being made, and what is known of the offset where it is (for the padding):
/// `offset % modulus` (`modulus` 1, 2, 4 or 8).
struct Make<'p, 'r> {
    plan: &'p Plan<'r>,
    ops: Vec<Op<'r>>,
    offset: usize,
    modulus: usize,
}

impl<'r> Make<'_, 'r> {
    /// Appends an op of `kind` and returns its index, unless the tape is full.
    fn push(&mut self, kind: Kind, name: &'r str) -> Option<usize> {
        if self.ops.len() >= MAX_OPS {
            return None;
        }
        self.ops.push(Op {
            kind,
            pad: DYNAMIC,
            pad_elem: DYNAMIC,
            elem: None,
            fixed: false,
            time: false,
            n: 0,
            end: self.ops.len() + 1,
            seen: AtomicUsize::new(0),
            seen_fields: AtomicUsize::new(0),
            name,
        });
        Some(self.ops.len() - 1)
    }

    /// The padding before `size` bytes aligned to `size`, then past them.
    fn put(&mut self, size: usize) -> u8 {
        let pad = self.pad(size);
        if pad == DYNAMIC {
            // Aligned to `size` at run time: known to that much from here.
            (self.modulus, self.offset) = (size, 0);
        } else {
            self.offset += pad as usize;
        }
        self.offset = (self.offset + size) % self.modulus;
        pad
    }

    /// The padding before `size` bytes aligned to `size`, if known.
    fn pad(&self, size: usize) -> u8 {
        if self.modulus >= size {
            (self.offset.wrapping_neg() & (size - 1)) as u8
        } else {
            DYNAMIC
        }
    }

    /// Past a number of bytes not known here, the offset known to `modulus` at most.
    fn lose(&mut self, modulus: usize) {
        self.modulus = self.modulus.min(modulus);
        self.offset %= self.modulus;
    }

    /// The message of the plan's node `n`, then its fields.
    fn node(&mut self, n: usize, name: &'r str) -> Option<()> {
        let node = &self.plan.nodes[n];
        let at = self.push(Kind::Struct, name)?;
        self.ops[at].n = u32::try_from(node.slots.len()).ok()?;
        self.ops[at].time = node.builtin == Builtin::Time;
        if node.slots.is_empty() {
            self.put(1);
        }
        for slot in &node.slots {
            self.field(slot)?;
        }
        self.ops[at].end = self.ops.len();
        Some(())
    }

    fn field(&mut self, slot: &Slot<'r>) -> Option<()> {
        let (fixed, n) = match slot.arity {
            Arity::Single => return self.element(&slot.elem, slot.name),
            Arity::Fixed(n) => (true, n),
            Arity::Bounded(n) => (false, n),
            Arity::Unbounded => (false, u32::MAX),
        };
        let at = self.push(Kind::Seq, slot.name)?;
        let op = &mut self.ops[at];
        (op.fixed, op.n) = (fixed, n);
        let pad = if fixed { 0 } else { self.put(4) };
        match slot.elem {
            Elem::Prim(p) => {
                let size = p.size();
                self.ops[at].elem = Some(norm(p));
                self.ops[at].pad = pad;
                match fixed {
                    true if n > 0 => {
                        self.ops[at].pad_elem = self.put(size);
                        let rest = (n as usize - 1) * size;
                        self.offset = (self.offset + rest) % self.modulus;
                    }
                    true => {}
                    false => {
                        // No padding if empty; after it, aligned to the element or to 4.
                        self.ops[at].pad_elem = self.pad(size);
                        self.lose(size.min(4));
                    }
                }
            }
            _ => {
                self.ops[at].pad = pad;
                // Each element starts where the last ended: nothing known.
                self.lose(1);
                self.element(&slot.elem, "")?;
                self.lose(1);
            }
        }
        self.ops[at].end = self.ops.len();
        Some(())
    }

    fn element(&mut self, elem: &Elem, name: &'r str) -> Option<()> {
        match *elem {
            Elem::Prim(p) => {
                let at = self.push(Kind::Prim(norm(p)), name)?;
                self.ops[at].pad = self.put(p.size());
            }
            Elem::Str(bound) => {
                let at = self.push(Kind::Str, name)?;
                self.ops[at].n = bound.unwrap_or(u32::MAX);
                self.ops[at].pad = self.put(4);
                self.lose(1);
            }
            Elem::WStr => return None,
            Elem::Msg(n) => self.node(n, name)?,
        }
        Some(())
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
    ser::write(&tape.ops, value, buf).map(drop)
}

/// The trusted reader alone, whether or not `T` was found to mirror the message (for
/// tests: it must read what the tape reads, or miss). A miss where the message's
/// layout does not qualify.
pub(crate) fn read_trusted<T: DeserializeOwned>(tape: &Tape<'_>, bytes: &[u8]) -> Result<T, Miss> {
    trusted_read::read(tape.layout.as_ref().ok_or(Miss)?, bytes)
}

/// [`Tape::read`] whatever the hint says (for tests).
pub(crate) fn read_any<T: DeserializeOwned>(tape: &Tape<'_>, bytes: &[u8]) -> Result<T, Miss> {
    de::read(&tape.ops, bytes).map(|(value, _)| value)
}
