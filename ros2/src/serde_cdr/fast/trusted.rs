//! Writing a value of a type already found to mirror the message (see `mod.rs`): XCDR1's
//! own rules and nothing else, the tape consulted only for sequences.
//!
//! A message qualifies if its layout does not depend on the sample beyond sequence
//! lengths and string contents: no sequence of messages (each element would be a place
//! the type's fields go unchecked in a sample where the sequence is empty) and no
//! bounded string (the bound belongs to a place on the tape). Then every value of a type
//! that serde visits the same way every time (a derived `Serialize` does) visits exactly
//! what one checked sample visited: each primitive is written aligned to its own size
//! counted from after the header, each string as its `u32` length with the NUL, its
//! bytes and the NUL, each sequence, in turn, as the next one on the tape says (its
//! count and bound, or a fixed array's length; its elements' type checked). What is
//! still checked in every sample: the number of fields visited (a field skipped by
//! `skip_serializing_if` is a miss) and of sequences, each sequence's length against
//! the tape and its elements' type, each string's NUL.

use super::packed::Packed;
use super::{Miss, Op};
use crate::def::Primitive;
use crate::wire::HEADER;
use serde::ser::{self, Impossible, Serialize};

/// What a refused compound gives (see `miss!`).
type No = Impossible<(), Miss>;

/// A sequence on the tape.
#[derive(Clone, Copy)]
pub(super) struct SeqOp {
    pub fixed: bool,
    pub n: u32,
    /// Of a primitive (packed), else of strings.
    pub elem: Option<Primitive>,
}

/// What the trusted writer (and reader, `trusted_read.rs`) needs of a tape that
/// qualifies.
pub(super) struct Layout {
    pub seqs: Vec<SeqOp>,
    /// The fields a mirroring type visits (a Time's two as `Timestamp`'s one `nanos`).
    pub fields: usize,
}

impl Layout {
    /// The layout of `ops`, if it qualifies.
    pub fn new(ops: &[Op<'_>]) -> Option<Layout> {
        use super::Kind;
        let mut seqs = Vec::new();
        let (mut fields, mut times) = (0, 0);
        for (i, op) in ops.iter().enumerate() {
            match op.kind {
                Kind::Str if op.n != u32::MAX => return None,
                // A sequence of messages.
                Kind::Seq
                    if op.elem.is_none()
                        && ops.get(i + 1).map(|body| body.kind) != Some(Kind::Str) =>
                {
                    return None
                }
                _ => {}
            }
            if op.kind == Kind::Seq {
                seqs.push(SeqOp {
                    fixed: op.fixed,
                    n: op.n,
                    elem: op.elem,
                });
            }
            fields += usize::from(!op.name.is_empty());
            times += usize::from(op.kind == Kind::Struct && op.time);
        }
        Some(Layout {
            seqs,
            fields: fields - times,
        })
    }
}

/// Writes `value` into `buf` (header first) as `layout` says, or misses.
pub(super) fn write<T: Serialize + ?Sized>(
    layout: &Layout,
    value: &T,
    buf: &mut Vec<u8>,
) -> Result<(), Miss> {
    let mut m = M {
        buf: std::mem::take(buf),
        seqs: &layout.seqs,
        next: 0,
        fields: 0,
    };
    m.buf.clear();
    m.buf.extend_from_slice(&HEADER);
    let done = value.serialize(Min {
        m: &mut m,
        nanos: false,
    });
    let all = m.next == layout.seqs.len() && m.fields == layout.fields;
    *buf = m.buf;
    done.and(if all { Ok(()) } else { Err(Miss) })
}

/// The sample being written, the next sequence and the fields visited.
struct M<'l> {
    buf: Vec<u8>,
    seqs: &'l [SeqOp],
    next: usize,
    fields: usize,
}

impl M<'_> {
    /// A primitive of `N` bytes, aligned to `N` counted from after the header.
    #[inline(always)]
    fn put<const N: usize>(&mut self, bytes: [u8; N]) {
        let pad = HEADER.len().wrapping_sub(self.buf.len()) & (N - 1);
        if pad != 0 {
            self.pad(pad);
        }
        self.buf.extend_from_slice(&bytes);
    }

    /// `pad` (at most 7) zero bytes: eight written, the rest cut (no call, no loop).
    #[inline(never)]
    fn pad(&mut self, pad: usize) {
        let len = self.buf.len();
        self.buf.extend_from_slice(&[0; 8]);
        self.buf.truncate(len + pad);
    }

    /// The next sequence, of `len` elements: its count written (not a fixed array's).
    #[inline(always)]
    fn seq(&mut self, len: usize) -> Result<SeqOp, Miss> {
        let seq = *self.seqs.get(self.next).ok_or(Miss)?;
        self.next += 1;
        if seq.fixed {
            return if len == seq.n as usize {
                Ok(seq)
            } else {
                Err(Miss)
            };
        }
        match u32::try_from(len) {
            Ok(len) if len <= seq.n => {
                self.put(len.to_le_bytes());
                Ok(seq)
            }
            _ => Err(Miss),
        }
    }

    #[inline]
    fn string(&mut self, v: &str) -> Result<(), Miss> {
        if has_nul(v.as_bytes()) {
            return Err(Miss);
        }
        let len = u32::try_from(v.len() + 1).map_err(|_| Miss)?;
        self.put(len.to_le_bytes());
        self.buf.extend_from_slice(v.as_bytes());
        self.buf.push(0);
        Ok(())
    }
}

/// Whether `bytes` hold a NUL (a short string, a frame id, is checked 8 bytes at a
/// time here rather than by a call).
#[inline(always)]
fn has_nul(bytes: &[u8]) -> bool {
    if bytes.len() > 32 {
        return bytes.contains(&0);
    }
    const ONES: u64 = u64::from_le_bytes([0x01; 8]);
    const HIGHS: u64 = u64::from_le_bytes([0x80; 8]);
    let mut chunks = bytes.chunks_exact(8);
    let words = (chunks.by_ref()).map(|c| u64::from_le_bytes(c.try_into().unwrap_or([1; 8])));
    // `(w - ONES) & !w & HIGHS` is non-zero exactly when a byte of `w` is zero.
    let zero_in = |w: u64| w.wrapping_sub(ONES) & !w & HIGHS != 0;
    let mut found = false;
    for w in words {
        found |= zero_in(w);
    }
    found || chunks.remainder().contains(&0)
}

/// Serializes one value of a mirroring type.
struct Min<'a, 'l> {
    m: &'a mut M<'l>,
    /// `Timestamp::nanos`: a Time's two fields.
    nanos: bool,
}

macro_rules! prims {
    ($($name:ident $t:ty),*) => {
        $(#[inline(always)]
        fn $name(self, v: $t) -> Result<(), Miss> {
            self.m.put(v.to_le_bytes());
            Ok(())
        })*
    };
}

impl<'a, 'l> ser::Serializer for Min<'a, 'l> {
    type Ok = ();
    type Error = Miss;
    type SerializeSeq = Seq<'a, 'l>;
    type SerializeTuple = Seq<'a, 'l>;
    type SerializeTupleStruct = Seq<'a, 'l>;
    type SerializeTupleVariant = No;
    type SerializeMap = No;
    type SerializeStruct = Struct<'a, 'l>;
    type SerializeStructVariant = No;

    miss! { char none some unit variants map }

    prims! {
        serialize_i8 i8, serialize_i16 i16, serialize_i32 i32, serialize_u8 u8,
        serialize_u16 u16, serialize_u32 u32, serialize_u64 u64, serialize_f32 f32,
        serialize_f64 f64
    }

    #[inline(always)]
    fn serialize_bool(self, v: bool) -> Result<(), Miss> {
        self.m.put([u8::from(v)]);
        Ok(())
    }
    #[inline(always)]
    fn serialize_i64(self, v: i64) -> Result<(), Miss> {
        if self.nanos {
            // builtin_interfaces/msg/Time: int32 sec (floor), uint32 nanosec.
            let sec = i32::try_from(v.div_euclid(1_000_000_000)).map_err(|_| Miss)?;
            self.m.put(sec.to_le_bytes());
            self.m
                .put((v.rem_euclid(1_000_000_000) as u32).to_le_bytes());
            return Ok(());
        }
        self.m.put(v.to_le_bytes());
        Ok(())
    }
    #[inline]
    fn serialize_str(self, v: &str) -> Result<(), Miss> {
        self.m.string(v)
    }
    fn serialize_bytes(self, v: &[u8]) -> Result<(), Miss> {
        if self.m.seq(v.len())?.elem != Some(Primitive::UInt8) {
            return Err(Miss);
        }
        self.m.buf.extend_from_slice(v);
        Ok(())
    }
    #[inline(always)]
    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        value: &T,
    ) -> Result<(), Miss> {
        value.serialize(self)
    }
    #[inline(always)]
    fn serialize_seq(self, len: Option<usize>) -> Result<Seq<'a, 'l>, Miss> {
        Seq::new(self.m, len.ok_or(Miss)?)
    }
    #[inline]
    fn serialize_tuple(self, len: usize) -> Result<Seq<'a, 'l>, Miss> {
        Seq::new(self.m, len)
    }
    #[inline]
    fn serialize_tuple_struct(self, _: &'static str, len: usize) -> Result<Seq<'a, 'l>, Miss> {
        Seq::new(self.m, len)
    }
    #[inline(always)]
    fn serialize_struct(self, name: &'static str, len: usize) -> Result<Struct<'a, 'l>, Miss> {
        // Found at a Time and only there in the checked sample (see `ser.rs`).
        let nanos = len == 1 && name == "Timestamp";
        // Fields counted by struct (a field skipped by `skip_serializing_if` is not
        // counted in `len`).
        self.m.fields += if nanos { 1 } else { len };
        if len == 0 {
            // rosidl's placeholder member of an empty structure.
            self.m.buf.push(0);
        }
        Ok(Struct { m: self.m, nanos })
    }
}

/// The fields of a struct.
struct Struct<'a, 'l> {
    m: &'a mut M<'l>,
    nanos: bool,
}

impl ser::SerializeStruct for Struct<'_, '_> {
    type Ok = ();
    type Error = Miss;

    #[inline(always)]
    fn serialize_field<T: Serialize + ?Sized>(
        &mut self,
        _: &'static str,
        value: &T,
    ) -> Result<(), Miss> {
        value.serialize(Min {
            m: self.m,
            nanos: self.nanos,
        })
    }

    #[inline(always)]
    fn end(self) -> Result<(), Miss> {
        Ok(())
    }
}

/// The elements of a sequence.
enum Seq<'a, 'l> {
    /// Of a primitive (see `packed.rs`), aligned before the first element.
    Packed(Packed<'a>),
    /// Of strings: the sample and the number of strings left to write.
    Strings { m: &'a mut M<'l>, left: usize },
    /// An element was not what the sequence holds, or one too many: a miss at the end.
    Spoilt,
}

impl<'a, 'l> Seq<'a, 'l> {
    #[inline(always)]
    fn new(m: &'a mut M<'l>, len: usize) -> Result<Self, Miss> {
        let seq = m.seq(len)?;
        let Some(elem) = seq.elem else {
            return Ok(Seq::Strings { m, left: len });
        };
        if len > 0 {
            let pad = HEADER.len().wrapping_sub(m.buf.len()) & (elem.size() - 1);
            if pad != 0 {
                m.pad(pad);
            }
        }
        Packed::new(&mut m.buf, elem, len).map(Seq::Packed)
    }

    #[inline(always)]
    fn element<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Miss> {
        let done = value.serialize(Item { seq: self });
        if done.is_err() {
            *self = Seq::Spoilt;
        }
        done
    }

    #[inline(always)]
    fn finish(self) -> Result<(), Miss> {
        let all = match self {
            Seq::Packed(packed) => packed.full(),
            Seq::Strings { left, .. } => left == 0,
            Seq::Spoilt => false,
        };
        if all {
            Ok(())
        } else {
            Err(Miss)
        }
    }
}

seq_impls! {
    SerializeSeq serialize_element, SerializeTuple serialize_element,
    SerializeTupleStruct serialize_field
}

/// One element of a sequence.
struct Item<'s, 'a, 'l> {
    seq: &'s mut Seq<'a, 'l>,
}

impl Item<'_, '_, '_> {
    #[inline(always)]
    fn fill<const N: usize>(self, p: Primitive, bytes: [u8; N]) -> Result<(), Miss> {
        match self.seq {
            Seq::Packed(packed) => packed.fill(p, bytes),
            _ => Err(Miss),
        }
    }
}

macro_rules! packed {
    ($($name:ident $p:ident $t:ty),*) => {
        $(#[inline(always)]
        fn $name(self, v: $t) -> Result<(), Miss> {
            self.fill(Primitive::$p, v.to_le_bytes())
        })*
    };
}

impl ser::Serializer for Item<'_, '_, '_> {
    type Ok = ();
    type Error = Miss;
    type SerializeSeq = No;
    type SerializeTuple = No;
    type SerializeTupleStruct = No;
    type SerializeTupleVariant = No;
    type SerializeMap = No;
    type SerializeStruct = No;
    type SerializeStructVariant = No;

    miss! { char none some unit variants map }

    packed! {
        serialize_i8 Int8 i8, serialize_i16 Int16 i16, serialize_i32 Int32 i32,
        serialize_i64 Int64 i64, serialize_u8 UInt8 u8, serialize_u16 UInt16 u16,
        serialize_u32 UInt32 u32, serialize_u64 UInt64 u64, serialize_f32 Float32 f32,
        serialize_f64 Float64 f64
    }

    #[inline(always)]
    fn serialize_bool(self, v: bool) -> Result<(), Miss> {
        self.fill(Primitive::Bool, [u8::from(v)])
    }
    fn serialize_str(self, v: &str) -> Result<(), Miss> {
        match self.seq {
            Seq::Strings { m, left } if *left > 0 => {
                *left -= 1;
                m.string(v)
            }
            _ => Err(Miss),
        }
    }
    fn serialize_bytes(self, _: &[u8]) -> Result<(), Miss> {
        Err(Miss)
    }
    #[inline(always)]
    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        value: &T,
    ) -> Result<(), Miss> {
        value.serialize(self)
    }
    fn serialize_seq(self, _: Option<usize>) -> Result<No, Miss> {
        Err(Miss)
    }
    fn serialize_tuple(self, _: usize) -> Result<No, Miss> {
        Err(Miss)
    }
    fn serialize_tuple_struct(self, _: &'static str, _: usize) -> Result<No, Miss> {
        Err(Miss)
    }
    fn serialize_struct(self, _: &'static str, _: usize) -> Result<No, Miss> {
        Err(Miss)
    }
}
