//! Reading a sample as a type already found to mirror the message (see `mod.rs`): the
//! reading side of `trusted.rs`, for the same messages (the same [`Layout`]).
//!
//! A type whose `Deserialize` went along the tape once (every Time a `Timestamp`, no
//! `Timestamp` elsewhere) asks, for every sample, for the same fields with the same
//! primitive types, as a derived `Deserialize` does. Each primitive is then read aligned
//! to its own size counted from after the header, with one bounds check, and no op is
//! consulted but for sequences. Every sample is still checked as the tape reader checks
//! it where the bytes decide: each length against the bytes left before anything is
//! allocated, each sequence's count against its bound (a fixed array's length against
//! the port's), each string's NUL and UTF-8, each `bool` 0 or 1, no more than 3 bytes
//! left at the end; and, as the trusted writer does, the number of fields read and of
//! sequences. Anything else is a [`Miss`]: the caller reads the sample along the tape.

use super::de::PackedSeq;
use super::read::{read_at, take_at, text_of};
use super::trusted::{Layout, SeqOp};
use super::Miss;
use crate::def::Primitive;
use crate::wire::HEADER;
use serde::de::value::I64Deserializer;
use serde::de::{self, DeserializeOwned, DeserializeSeed, SeqAccess, Visitor};

/// Reads a sample as a `T`, the message's layout being `layout`.
pub(super) fn read<T: DeserializeOwned>(layout: &Layout, bytes: &[u8]) -> Result<T, Miss> {
    // Little-endian plain CDR (the plan path explains any other header).
    if !matches!(bytes, [0x00, 0x01, _, _, ..]) {
        return Err(Miss);
    }
    let mut r = R {
        data: bytes,
        at: HEADER.len(),
        seqs: &layout.seqs,
        next: 0,
        fields: 0,
    };
    let value = T::deserialize(Tin { r: &mut r })?;
    // Writers may pad a sample to a multiple of 4.
    let all = r.next == layout.seqs.len() && r.fields == layout.fields;
    if !all || r.data.len() - r.at > 3 {
        return Err(Miss);
    }
    Ok(value)
}

/// The sample being read, the next sequence and the fields read.
struct R<'l, 'd> {
    data: &'d [u8],
    /// The offset in the sample (the header counted).
    at: usize,
    seqs: &'l [SeqOp],
    next: usize,
    fields: usize,
}

impl<'d> R<'_, 'd> {
    /// A primitive of `N` bytes, aligned to `N` counted from after the header.
    #[inline(always)]
    fn get<const N: usize>(&mut self) -> Result<[u8; N], Miss> {
        let start = self.at + (HEADER.len().wrapping_sub(self.at) & (N - 1));
        read_at(self.data, &mut self.at, start)
    }

    #[inline(always)]
    fn take(&mut self, n: usize) -> Result<&'d [u8], Miss> {
        take_at(self.data, &mut self.at, n)
    }

    /// The next sequence, its elements taking at least `min` bytes each (`None`: its
    /// element's size): the sequence and its number of elements, refused if the rest
    /// of the sample cannot hold them.
    #[inline(always)]
    fn seq(&mut self, min: Option<usize>) -> Result<(SeqOp, usize), Miss> {
        let seq = *self.seqs.get(self.next).ok_or(Miss)?;
        self.next += 1;
        let len = if seq.fixed {
            seq.n
        } else {
            let len = u32::from_le_bytes(self.get()?);
            if len > seq.n {
                return Err(Miss);
            }
            len
        } as usize;
        let min = min.or(seq.elem.map(Primitive::size)).unwrap_or(5);
        if len.saturating_mul(min) > self.data.len() - self.at {
            return Err(Miss);
        }
        Ok((seq, len))
    }

    /// A string: its length (counting the NUL), its UTF-8 bytes, the NUL.
    #[inline]
    fn string(&mut self) -> Result<&'d str, Miss> {
        let len = u32::from_le_bytes(self.get()?) as usize;
        text_of(self.take(len)?)
    }
}

/// Deserializes one value of a mirroring type.
struct Tin<'a, 'l, 'd> {
    r: &'a mut R<'l, 'd>,
}

/// The primitives: each read as wide as the port's type says (the checked sample
/// found them the message's).
macro_rules! prims {
    ($($name:ident $visit:ident $t:ty),*) => {
        $(#[inline(always)]
        fn $name<V: Visitor<'d>>(self, v: V) -> Result<V::Value, Miss> {
            v.$visit(<$t>::from_le_bytes(self.r.get()?))
        })*
    };
}

impl<'d> de::Deserializer<'d> for Tin<'_, '_, 'd> {
    type Error = Miss;

    prims! {
        deserialize_i8 visit_i8 i8, deserialize_i16 visit_i16 i16,
        deserialize_i32 visit_i32 i32, deserialize_i64 visit_i64 i64,
        deserialize_u8 visit_u8 u8, deserialize_u16 visit_u16 u16,
        deserialize_u32 visit_u32 u32, deserialize_u64 visit_u64 u64,
        deserialize_f32 visit_f32 f32, deserialize_f64 visit_f64 f64
    }

    de_shared!('d);

    #[inline]
    fn deserialize_bool<V: Visitor<'d>>(self, v: V) -> Result<V::Value, Miss> {
        match self.r.get::<1>()? {
            [b @ (0 | 1)] => v.visit_bool(b == 1),
            _ => Err(Miss),
        }
    }
    #[inline]
    fn deserialize_str<V: Visitor<'d>>(self, v: V) -> Result<V::Value, Miss> {
        v.visit_str(self.r.string()?)
    }
    fn deserialize_bytes<V: Visitor<'d>>(self, v: V) -> Result<V::Value, Miss> {
        let (seq, len) = self.r.seq(Some(1))?;
        if seq.elem != Some(Primitive::UInt8) {
            return Err(Miss);
        }
        v.visit_bytes(self.r.take(len)?)
    }
    #[inline(always)]
    fn deserialize_struct<V: Visitor<'d>>(
        self,
        name: &'static str,
        fields: &'static [&'static str],
        v: V,
    ) -> Result<V::Value, Miss> {
        if name == "Timestamp" && fields == ["nanos"] {
            // Found at a Time and only there in the checked sample.
            let sec = i32::from_le_bytes(self.r.get()?);
            let nanosec = u32::from_le_bytes(self.r.get()?);
            self.r.fields += 1;
            let nanos = i64::from(sec) * 1_000_000_000 + i64::from(nanosec);
            return v.visit_seq(Nanos(Some(nanos)));
        }
        if fields.is_empty() {
            // rosidl's placeholder member of an empty structure.
            self.r.take(1)?;
        }
        v.visit_seq(Fields {
            r: self.r,
            left: fields.len(),
        })
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

impl<'d> Tin<'_, '_, 'd> {
    /// The next sequence; `want`: the length of a Rust array.
    #[inline]
    fn elements<V: Visitor<'d>>(self, want: Option<usize>, v: V) -> Result<V::Value, Miss> {
        let (seq, len) = self.r.seq(None)?;
        if want.is_some_and(|n| n != len) {
            return Err(Miss);
        }
        match seq.elem {
            Some(p) => {
                if len > 0 {
                    let pad = HEADER.len().wrapping_sub(self.r.at) & (p.size() - 1);
                    self.r.take(pad)?;
                }
                v.visit_seq(PackedSeq::new(self.r.take(len * p.size())?, p, len))
            }
            None => {
                let mut strings = Strings {
                    r: self.r,
                    left: len,
                };
                let value = v.visit_seq(&mut strings)?;
                if strings.left != 0 {
                    return Err(Miss);
                }
                Ok(value)
            }
        }
    }
}

/// A struct's fields, each counted as read.
struct Fields<'a, 'l, 'd> {
    r: &'a mut R<'l, 'd>,
    left: usize,
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
        self.r.fields += 1;
        seed.deserialize(Tin { r: self.r }).map(Some)
    }
    fn size_hint(&self) -> Option<usize> {
        Some(self.left)
    }
}

/// `Timestamp`'s one field, `nanos`, read already from a Time's two.
struct Nanos(Option<i64>);

impl<'d> SeqAccess<'d> for Nanos {
    type Error = Miss;
    fn next_element_seed<T: DeserializeSeed<'d>>(
        &mut self,
        seed: T,
    ) -> Result<Option<T::Value>, Miss> {
        match self.0.take() {
            Some(nanos) => seed.deserialize(I64Deserializer::new(nanos)).map(Some),
            None => Ok(None),
        }
    }
    fn size_hint(&self) -> Option<usize> {
        Some(usize::from(self.0.is_some()))
    }
}

/// The elements of a sequence of strings.
struct Strings<'a, 'l, 'd> {
    r: &'a mut R<'l, 'd>,
    left: usize,
}

impl<'d> SeqAccess<'d> for Strings<'_, '_, 'd> {
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
        seed.deserialize(Str { r: self.r }).map(Some)
    }
    fn size_hint(&self) -> Option<usize> {
        Some(self.left)
    }
}

/// One string of a sequence of strings (nothing else is taken).
struct Str<'a, 'l, 'd> {
    r: &'a mut R<'l, 'd>,
}

impl<'de> de::Deserializer<'de> for Str<'_, '_, 'de> {
    type Error = Miss;

    #[inline]
    fn deserialize_str<V: Visitor<'de>>(self, v: V) -> Result<V::Value, Miss> {
        v.visit_str(self.r.string()?)
    }
    #[inline]
    fn deserialize_string<V: Visitor<'de>>(self, v: V) -> Result<V::Value, Miss> {
        self.deserialize_str(v)
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
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char bytes byte_buf option
        unit unit_struct seq tuple tuple_struct map struct enum identifier ignored_any
    }

    fn is_human_readable(&self) -> bool {
        false
    }
}
