//! Reading a value along the tape (see `mod.rs`). Bounded as the plan path is: every
//! length is checked against the bytes left before anything is allocated, and anything
//! unexpected is a [`Miss`] (the plan path then says what is wrong).

use super::read::{read_at, take_at, text_of};
use super::{Kind, Miss, Op, DYNAMIC, NANOS};
use crate::def::Primitive;
use crate::wire::HEADER;
use serde::de::{self, DeserializeOwned, DeserializeSeed, SeqAccess, Visitor};

/// Reads a sample of the message of `ops` as a `T`; with whether the trusted reader may
/// read values of this type from now on (every Time was read as a `Timestamp`, and only
/// Times were; see `trusted_read.rs`).
pub(super) fn read<T: DeserializeOwned>(ops: &[Op<'_>], bytes: &[u8]) -> Result<(T, bool), Miss> {
    // Little-endian plain CDR (the plan path explains any other header).
    if !matches!(bytes, [0x00, 0x01, _, _, ..]) {
        return Err(Miss);
    }
    let mut r = R {
        ops,
        pos: 0,
        data: bytes,
        at: HEADER.len(),
        trustable: true,
    };
    let value = T::deserialize(De::at(&mut r, 0)?)?;
    // Writers may pad a sample to a multiple of 4.
    if r.data.len() - r.at > 3 {
        return Err(Miss);
    }
    Ok((value, r.trustable))
}

/// The sample being read and the op next on the tape.
struct R<'t, 'd> {
    ops: &'t [Op<'t>],
    pos: usize,
    data: &'d [u8],
    /// The offset in the sample (the header counted).
    at: usize,
    trustable: bool,
}

impl<'d> R<'_, 'd> {
    /// A primitive of `N` bytes after `pad` bytes of padding (known from the tape, or
    /// [`DYNAMIC`]: to a multiple of `N`), with one bounds check.
    #[inline(always)]
    fn get<const N: usize>(&mut self, pad: u8) -> Result<[u8; N], Miss> {
        let start = match pad {
            0 => self.at,
            DYNAMIC => self.at + (HEADER.len().wrapping_sub(self.at) & (N - 1)),
            pad => self.at + pad as usize,
        };
        read_at(self.data, &mut self.at, start)
    }

    #[inline(always)]
    fn take(&mut self, n: usize) -> Result<&'d [u8], Miss> {
        take_at(self.data, &mut self.at, n)
    }

    /// Skips the padding before the first element of an array of `p`.
    #[inline(always)]
    fn pad(&mut self, pad: u8, p: Primitive) -> Result<(), Miss> {
        let pad = match pad {
            DYNAMIC => HEADER.len().wrapping_sub(self.at) & (p.size() - 1),
            pad => pad as usize,
        };
        self.take(pad).map(drop)
    }

    /// The number of elements of the array or sequence `op` whose elements take at
    /// least `min` bytes each, refused if the rest of the sample cannot hold them.
    #[inline(always)]
    fn count(&mut self, op: &Op<'_>, min: usize) -> Result<usize, Miss> {
        let len = if op.fixed {
            op.n
        } else {
            let len = u32::from_le_bytes(self.get(op.pad)?);
            if len > op.n {
                return Err(Miss);
            }
            len
        };
        let len = len as usize;
        if len.saturating_mul(min) > self.data.len() - self.at {
            return Err(Miss);
        }
        Ok(len)
    }

    /// A string of at most `bound` bytes: its length (counting the NUL) after `pad`,
    /// its UTF-8 bytes, the NUL.
    #[inline]
    fn string(&mut self, pad: u8, bound: u32) -> Result<&'d str, Miss> {
        let len = u32::from_le_bytes(self.get(pad)?) as usize;
        if len > bound as usize + 1 {
            return Err(Miss);
        }
        text_of(self.take(len)?)
    }
}

/// Deserializes one value as the op `op` says.
struct De<'a, 't, 'd> {
    r: &'a mut R<'t, 'd>,
    op: &'t Op<'t>,
}

impl<'a, 't, 'd> De<'a, 't, 'd> {
    /// The op at `i`, the tape moved past it (to what it contains).
    #[inline(always)]
    fn at(r: &'a mut R<'t, 'd>, i: usize) -> Result<Self, Miss> {
        let ops: &'t [Op<'t>] = r.ops;
        let op = ops.get(i).ok_or(Miss)?;
        r.pos = i + 1;
        Ok(De { r, op })
    }

    /// An array or sequence; `want`: the length of a Rust array.
    #[inline]
    fn elements<V: Visitor<'d>>(self, want: Option<usize>, v: V) -> Result<V::Value, Miss> {
        let op = self.op;
        if op.kind != Kind::Seq {
            return Err(Miss);
        }
        let value = match op.elem {
            Some(p) => {
                let len = self.r.count(op, p.size())?;
                if want.is_some_and(|n| n != len) {
                    return Err(Miss);
                }
                if len > 0 {
                    self.r.pad(op.pad_elem, p)?;
                }
                // By value (in registers): a visitor that stops early leaves the rest
                // of these bytes unread, the sample's offset is past them all the same.
                v.visit_seq(PackedSeq::new(self.r.take(len * p.size())?, p, len))?
            }
            None => {
                let body = self.r.pos;
                let min = match self.r.ops.get(body).map(|op| op.kind) {
                    Some(Kind::Str) => 5,
                    _ => 1,
                };
                let len = self.r.count(op, min)?;
                if want.is_some_and(|n| n != len) {
                    return Err(Miss);
                }
                let mut each = Each {
                    r: self.r,
                    body,
                    left: len,
                };
                let value = v.visit_seq(&mut each)?;
                if each.left != 0 {
                    return Err(Miss);
                }
                value
            }
        };
        self.r.pos = op.end;
        Ok(value)
    }

    /// A message's fields, the port's struct having the fields `names`.
    #[inline(always)]
    fn fields<V: Visitor<'d>>(
        self,
        len: u32,
        names: &'static [&'static str],
        v: V,
    ) -> Result<V::Value, Miss> {
        if !self.named(names) {
            return Err(Miss);
        }
        if len == 0 {
            // rosidl's placeholder member of an empty structure.
            self.r.take(1)?;
        }
        let value = v.visit_seq(Fields {
            r: self.r,
            left: len,
        })?;
        // Every field read (a visitor may stop early).
        if self.r.pos != self.op.end {
            return Err(Miss);
        }
        Ok(value)
    }

    /// Whether the struct's fields `names` are the message's, in order (compared once
    /// per list: the address of a derived `Deserialize`'s list is kept in the op).
    #[inline(always)]
    fn named(&self, names: &'static [&'static str]) -> bool {
        use std::sync::atomic::Ordering;
        let at = names.as_ptr() as usize;
        if self.op.seen_fields.load(Ordering::Relaxed) == at {
            return true;
        }
        self.named_slow(names)
    }

    #[cold]
    fn named_slow(&self, names: &'static [&'static str]) -> bool {
        let ops = self.r.ops;
        let mut i = self.r.pos;
        for name in names {
            match ops.get(i) {
                Some(op) if i < self.op.end && op.name == *name => i = op.end,
                _ => return false,
            }
        }
        let same = i == self.op.end;
        if same {
            let at = names.as_ptr() as usize;
            (self.op.seen_fields).store(at, std::sync::atomic::Ordering::Relaxed);
        }
        same
    }
}

/// The primitives, each read only into the port's type of the same width.
macro_rules! exact {
    ($($name:ident $p:ident $visit:ident $t:ty),*) => {
        $(#[inline(always)]
        fn $name<V: Visitor<'d>>(self, v: V) -> Result<V::Value, Miss> {
            if self.op.kind != Kind::Prim(Primitive::$p) {
                return Err(Miss);
            }
            v.$visit(<$t>::from_le_bytes(self.r.get(self.op.pad)?))
        })*
    };
}

impl<'d> de::Deserializer<'d> for De<'_, '_, 'd> {
    type Error = Miss;

    exact! {
        deserialize_i8 Int8 visit_i8 i8, deserialize_i16 Int16 visit_i16 i16,
        deserialize_i32 Int32 visit_i32 i32,
        deserialize_u8 UInt8 visit_u8 u8, deserialize_u16 UInt16 visit_u16 u16,
        deserialize_u32 UInt32 visit_u32 u32, deserialize_u64 UInt64 visit_u64 u64,
        deserialize_f32 Float32 visit_f32 f32, deserialize_f64 Float64 visit_f64 f64
    }

    de_shared!('d);

    #[inline(always)]
    fn deserialize_i64<V: Visitor<'d>>(self, v: V) -> Result<V::Value, Miss> {
        match self.op.kind {
            Kind::Prim(Primitive::Int64) => {
                v.visit_i64(i64::from_le_bytes(self.r.get(self.op.pad)?))
            }
            Kind::Nanos => {
                let sec = i32::from_le_bytes(self.r.get(DYNAMIC)?);
                let nanosec = u32::from_le_bytes(self.r.get(0)?);
                v.visit_i64(i64::from(sec) * 1_000_000_000 + i64::from(nanosec))
            }
            _ => Err(Miss),
        }
    }
    #[inline]
    fn deserialize_bool<V: Visitor<'d>>(self, v: V) -> Result<V::Value, Miss> {
        match (self.op.kind, self.r.get::<1>(0)?) {
            (Kind::Prim(Primitive::Bool), [b @ (0 | 1)]) => v.visit_bool(b == 1),
            _ => Err(Miss),
        }
    }
    #[inline]
    fn deserialize_str<V: Visitor<'d>>(self, v: V) -> Result<V::Value, Miss> {
        if self.op.kind != Kind::Str {
            return Err(Miss);
        }
        v.visit_str(self.r.string(self.op.pad, self.op.n)?)
    }
    fn deserialize_bytes<V: Visitor<'d>>(self, v: V) -> Result<V::Value, Miss> {
        if self.op.kind != Kind::Seq || self.op.elem != Some(Primitive::UInt8) {
            return Err(Miss);
        }
        let len = self.r.count(self.op, 1)?;
        v.visit_bytes(self.r.take(len)?)
    }
    #[inline(always)]
    fn deserialize_struct<V: Visitor<'d>>(
        self,
        name: &'static str,
        fields: &'static [&'static str],
        v: V,
    ) -> Result<V::Value, Miss> {
        if self.op.kind != Kind::Struct {
            return Err(Miss);
        }
        let timestamp = name == "Timestamp" && fields == ["nanos"];
        if self.op.time != timestamp {
            // A Time as its fields, or a `Timestamp` that is not a Time.
            self.r.trustable = false;
        }
        if self.op.time && timestamp {
            let value = v.visit_seq(Nanos { r: self.r })?;
            self.r.pos = self.op.end;
            return Ok(value);
        }
        let len = self.op.n;
        self.fields(len, fields, v)
    }
    fn deserialize_enum<V: Visitor<'d>>(
        self,
        _: &'static str,
        _: &'static [&'static str],
        _: V,
    ) -> Result<V::Value, Miss> {
        Err(Miss)
    }
    fn is_human_readable(&self) -> bool {
        false
    }
}

/// A message's fields: the ops next on the tape.
struct Fields<'a, 't, 'd> {
    r: &'a mut R<'t, 'd>,
    left: u32,
}

impl<'d> SeqAccess<'d> for Fields<'_, '_, 'd> {
    type Error = Miss;
    #[inline(always)]
    fn next_element_seed<T: DeserializeSeed<'d>>(
        &mut self,
        seed: T,
    ) -> Result<Option<T::Value>, Miss> {
        if self.left == 0 {
            return Ok(None);
        }
        self.left -= 1;
        let i = self.r.pos;
        seed.deserialize(De::at(self.r, i)?).map(Some)
    }
    fn size_hint(&self) -> Option<usize> {
        Some(self.left as usize)
    }
}

/// The elements of an array of strings or messages: the element's op, over again.
struct Each<'a, 't, 'd> {
    r: &'a mut R<'t, 'd>,
    body: usize,
    left: usize,
}

impl<'d> SeqAccess<'d> for Each<'_, '_, 'd> {
    type Error = Miss;
    #[inline]
    fn next_element_seed<T: DeserializeSeed<'d>>(
        &mut self,
        seed: T,
    ) -> Result<Option<T::Value>, Miss> {
        if self.left == 0 {
            return Ok(None);
        }
        self.left -= 1;
        seed.deserialize(De::at(self.r, self.body)?).map(Some)
    }
    fn size_hint(&self) -> Option<usize> {
        Some(self.left)
    }
}

/// `Timestamp`'s one field, `nanos`, from a Time's two.
struct Nanos<'a, 't, 'd> {
    r: &'a mut R<'t, 'd>,
}

impl<'d> SeqAccess<'d> for Nanos<'_, '_, 'd> {
    type Error = Miss;
    fn next_element_seed<T: DeserializeSeed<'d>>(
        &mut self,
        seed: T,
    ) -> Result<Option<T::Value>, Miss> {
        seed.deserialize(De {
            r: self.r,
            op: &NANOS,
        })
        .map(Some)
    }
    fn size_hint(&self) -> Option<usize> {
        Some(1)
    }
}

/// The elements of an array of the primitive `p`, from the array's bytes (taken whole:
/// no bounds to keep but theirs). Also the trusted reader's (`trusted_read.rs`).
pub(super) struct PackedSeq<'d> {
    bytes: &'d [u8],
    p: Primitive,
    len: usize,
}

impl<'d> PackedSeq<'d> {
    /// `len` elements of `p` in `bytes` (`len` times its size).
    #[inline(always)]
    pub fn new(bytes: &'d [u8], p: Primitive, len: usize) -> Self {
        PackedSeq { bytes, p, len }
    }
}

impl<'d> SeqAccess<'d> for PackedSeq<'d> {
    type Error = Miss;
    #[inline(always)]
    fn next_element_seed<T: DeserializeSeed<'d>>(
        &mut self,
        seed: T,
    ) -> Result<Option<T::Value>, Miss> {
        if self.bytes.is_empty() {
            return Ok(None);
        }
        seed.deserialize(Packed {
            bytes: &mut self.bytes,
            p: self.p,
        })
        .map(Some)
    }
    fn size_hint(&self) -> Option<usize> {
        Some(self.len)
    }
}

/// One element of an array of `p`.
struct Packed<'a, 'd> {
    bytes: &'a mut &'d [u8],
    p: Primitive,
}

impl Packed<'_, '_> {
    #[inline(always)]
    fn next<const N: usize>(&mut self, ours: Primitive) -> Result<[u8; N], Miss> {
        if self.p != ours {
            return Err(Miss);
        }
        match self.bytes.split_first_chunk::<N>() {
            Some((bytes, rest)) => {
                *self.bytes = rest;
                Ok(*bytes)
            }
            None => Err(Miss),
        }
    }
}

macro_rules! packed {
    ($($name:ident $p:ident $visit:ident $t:ty),*) => {
        $(#[inline(always)]
        fn $name<V: Visitor<'de>>(mut self, v: V) -> Result<V::Value, Miss> {
            v.$visit(<$t>::from_le_bytes(self.next(Primitive::$p)?))
        })*
    };
}

impl<'de> de::Deserializer<'de> for Packed<'_, 'de> {
    type Error = Miss;

    packed! {
        deserialize_i8 Int8 visit_i8 i8, deserialize_i16 Int16 visit_i16 i16,
        deserialize_i32 Int32 visit_i32 i32, deserialize_i64 Int64 visit_i64 i64,
        deserialize_u8 UInt8 visit_u8 u8, deserialize_u16 UInt16 visit_u16 u16,
        deserialize_u32 UInt32 visit_u32 u32, deserialize_u64 UInt64 visit_u64 u64,
        deserialize_f32 Float32 visit_f32 f32, deserialize_f64 Float64 visit_f64 f64
    }

    #[inline(always)]
    fn deserialize_bool<V: Visitor<'de>>(mut self, v: V) -> Result<V::Value, Miss> {
        match self.next::<1>(Primitive::Bool)? {
            [b @ (0 | 1)] => v.visit_bool(b == 1),
            _ => Err(Miss),
        }
    }
    #[inline(always)]
    fn deserialize_newtype_struct<V: Visitor<'de>>(
        self,
        _: &'static str,
        v: V,
    ) -> Result<V::Value, Miss> {
        v.visit_newtype_struct(self)
    }
    fn deserialize_any<V: Visitor<'de>>(self, _: V) -> Result<V::Value, Miss> {
        Err(Miss)
    }

    serde::forward_to_deserialize_any! {
        char str string bytes byte_buf option unit unit_struct seq tuple tuple_struct map
        struct enum identifier ignored_any
    }

    fn is_human_readable(&self) -> bool {
        false
    }
}
