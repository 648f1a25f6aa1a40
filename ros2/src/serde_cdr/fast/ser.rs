//! Writing a value along the tape (see `mod.rs`).

use super::{Kind, Miss, Op, NANOS};
use crate::def::Primitive;
use crate::wire::HEADER;
use serde::ser::{self, Impossible, Serialize};

/// Writes `value`, the message of `ops`, into `buf` (cleared first, capacity kept).
pub(super) fn write<T: Serialize + ?Sized>(
    ops: &[Op<'_>],
    value: &T,
    buf: &mut Vec<u8>,
) -> Result<(), Miss> {
    let mut w = W {
        ops,
        pos: 0,
        buf: std::mem::take(buf),
    };
    w.buf.clear();
    w.buf.extend_from_slice(&HEADER);
    let done = Ser::at(&mut w, 0).and_then(|s| value.serialize(s));
    *buf = w.buf;
    done
}

/// The sample being written and the op next on the tape.
struct W<'t> {
    ops: &'t [Op<'t>],
    pos: usize,
    buf: Vec<u8>,
}

impl W<'_> {
    /// A primitive of `N` bytes, aligned to `N` (counted from after the header).
    #[inline(always)]
    fn put<const N: usize>(&mut self, bytes: [u8; N]) {
        let pad = HEADER.len().wrapping_sub(self.buf.len()) & (N - 1);
        if pad != 0 {
            self.buf.resize(self.buf.len() + pad, 0);
        }
        self.buf.extend_from_slice(&bytes);
    }

    /// The count of a sequence, nothing for a fixed array (whose length must be its).
    #[inline(always)]
    fn count(&mut self, fixed: bool, max: u32, len: usize) -> Result<(), Miss> {
        if fixed {
            return if len == max as usize {
                Ok(())
            } else {
                Err(Miss)
            };
        }
        let len = u32::try_from(len).map_err(|_| Miss)?;
        if len > max {
            return Err(Miss);
        }
        self.put(len.to_le_bytes());
        Ok(())
    }
}

/// Serializes one value as the op `op` says.
struct Ser<'a, 't> {
    w: &'a mut W<'t>,
    op: &'t Op<'t>,
}

impl<'a, 't> Ser<'a, 't> {
    /// The op at `i`, the tape moved past it (to what it contains).
    #[inline(always)]
    fn at(w: &'a mut W<'t>, i: usize) -> Result<Self, Miss> {
        let ops: &'t [Op<'t>] = w.ops;
        let op = ops.get(i).ok_or(Miss)?;
        w.pos = i + 1;
        Ok(Ser { w, op })
    }

    #[inline(always)]
    fn prim<const N: usize>(self, ours: Primitive, bytes: [u8; N]) -> Result<(), Miss> {
        if self.op.kind != Kind::Prim(ours) {
            return Err(Miss);
        }
        self.w.put(bytes);
        Ok(())
    }

    /// An array or sequence of `len` elements.
    #[inline(always)]
    fn seq(self, len: usize) -> Result<Seq<'a, 't>, Miss> {
        let Kind::Seq { fixed, max, prim } = self.op.kind else {
            return Err(Miss);
        };
        self.w.count(fixed, max, len)?;
        let packed = match prim {
            Some(p) if len > 0 => {
                let size = p.size();
                let pad = HEADER.len().wrapping_sub(self.w.buf.len()) & (size - 1);
                self.w.buf.resize(self.w.buf.len() + pad, 0);
                self.w.buf.reserve(len * size);
                Some((p, self.w.buf.len() + len * size))
            }
            Some(p) => Some((p, self.w.buf.len())),
            None => None,
        };
        Ok(Seq {
            body: self.w.pos,
            end: self.op.end,
            w: self.w,
            packed,
            left: len,
        })
    }
}

/// Everything the tape does not take.
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

type No = Impossible<(), Miss>;

impl<'a, 't> ser::Serializer for Ser<'a, 't> {
    type Ok = ();
    type Error = Miss;
    type SerializeSeq = Seq<'a, 't>;
    type SerializeTuple = Seq<'a, 't>;
    type SerializeTupleStruct = Seq<'a, 't>;
    type SerializeTupleVariant = No;
    type SerializeMap = No;
    type SerializeStruct = Struct<'a, 't>;
    type SerializeStructVariant = No;

    miss! { char none some unit variants map }

    #[inline(always)]
    fn serialize_bool(self, v: bool) -> Result<(), Miss> {
        self.prim(Primitive::Bool, [u8::from(v)])
    }
    #[inline(always)]
    fn serialize_i8(self, v: i8) -> Result<(), Miss> {
        self.prim(Primitive::Int8, v.to_le_bytes())
    }
    #[inline(always)]
    fn serialize_i16(self, v: i16) -> Result<(), Miss> {
        self.prim(Primitive::Int16, v.to_le_bytes())
    }
    #[inline(always)]
    fn serialize_i32(self, v: i32) -> Result<(), Miss> {
        self.prim(Primitive::Int32, v.to_le_bytes())
    }
    #[inline(always)]
    fn serialize_i64(self, v: i64) -> Result<(), Miss> {
        if self.op.kind == Kind::Nanos {
            // builtin_interfaces/msg/Time: int32 sec (floor), uint32 nanosec.
            let sec = i32::try_from(v.div_euclid(1_000_000_000)).map_err(|_| Miss)?;
            self.w.put(sec.to_le_bytes());
            self.w
                .put((v.rem_euclid(1_000_000_000) as u32).to_le_bytes());
            return Ok(());
        }
        self.prim(Primitive::Int64, v.to_le_bytes())
    }
    #[inline(always)]
    fn serialize_u8(self, v: u8) -> Result<(), Miss> {
        self.prim(Primitive::UInt8, [v])
    }
    #[inline(always)]
    fn serialize_u16(self, v: u16) -> Result<(), Miss> {
        self.prim(Primitive::UInt16, v.to_le_bytes())
    }
    #[inline(always)]
    fn serialize_u32(self, v: u32) -> Result<(), Miss> {
        self.prim(Primitive::UInt32, v.to_le_bytes())
    }
    #[inline(always)]
    fn serialize_u64(self, v: u64) -> Result<(), Miss> {
        self.prim(Primitive::UInt64, v.to_le_bytes())
    }
    #[inline(always)]
    fn serialize_f32(self, v: f32) -> Result<(), Miss> {
        self.prim(Primitive::Float32, v.to_le_bytes())
    }
    #[inline(always)]
    fn serialize_f64(self, v: f64) -> Result<(), Miss> {
        self.prim(Primitive::Float64, v.to_le_bytes())
    }
    #[inline]
    fn serialize_str(self, v: &str) -> Result<(), Miss> {
        let Kind::Str(bound) = self.op.kind else {
            return Err(Miss);
        };
        if bound.is_some_and(|b| v.len() > b as usize) || v.as_bytes().contains(&0) {
            return Err(Miss);
        }
        let len = u32::try_from(v.len() + 1).map_err(|_| Miss)?;
        self.w.put(len.to_le_bytes());
        self.w.buf.extend_from_slice(v.as_bytes());
        self.w.buf.push(0);
        Ok(())
    }
    fn serialize_bytes(self, v: &[u8]) -> Result<(), Miss> {
        let Kind::Seq {
            fixed,
            max,
            prim: Some(Primitive::UInt8),
        } = self.op.kind
        else {
            return Err(Miss);
        };
        self.w.count(fixed, max, v.len())?;
        self.w.buf.extend_from_slice(v);
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
    #[inline]
    fn serialize_seq(self, len: Option<usize>) -> Result<Seq<'a, 't>, Miss> {
        self.seq(len.ok_or(Miss)?)
    }
    #[inline]
    fn serialize_tuple(self, len: usize) -> Result<Seq<'a, 't>, Miss> {
        self.seq(len)
    }
    #[inline]
    fn serialize_tuple_struct(self, _: &'static str, len: usize) -> Result<Seq<'a, 't>, Miss> {
        self.seq(len)
    }
    #[inline(always)]
    fn serialize_struct(self, name: &'static str, len: usize) -> Result<Struct<'a, 't>, Miss> {
        let Kind::Struct { len: fields, time } = self.op.kind else {
            return Err(Miss);
        };
        let time = time && len == 1 && name == "Timestamp";
        if !time && len != fields as usize {
            return Err(Miss);
        }
        if fields == 0 {
            // rosidl's placeholder member of an empty structure.
            self.w.buf.push(0);
        }
        Ok(Struct {
            end: self.op.end,
            w: self.w,
            time,
        })
    }
}

/// The fields of a struct, each the op next on the tape.
struct Struct<'a, 't> {
    w: &'a mut W<'t>,
    /// Where the message's ops end.
    end: usize,
    /// `Timestamp { nanos }` as `builtin_interfaces/msg/Time`.
    time: bool,
}

impl ser::SerializeStruct for Struct<'_, '_> {
    type Ok = ();
    type Error = Miss;

    #[inline(always)]
    fn serialize_field<T: Serialize + ?Sized>(
        &mut self,
        key: &'static str,
        value: &T,
    ) -> Result<(), Miss> {
        if self.time {
            return self.nanos(key, value);
        }
        let i = self.w.pos;
        let ops: &[Op<'_>] = self.w.ops;
        match ops.get(i) {
            Some(op) if op.named(key) => {
                self.w.pos = i + 1;
                value.serialize(Ser { w: self.w, op })
            }
            _ => Err(Miss),
        }
    }

    #[inline(always)]
    fn end(self) -> Result<(), Miss> {
        if self.w.pos == self.end {
            Ok(())
        } else {
            Err(Miss)
        }
    }
}

impl Struct<'_, '_> {
    /// `Timestamp::nanos`: the Time's two fields (once).
    #[cold]
    fn nanos<T: Serialize + ?Sized>(&mut self, key: &'static str, value: &T) -> Result<(), Miss> {
        if key != "nanos" || self.w.pos == self.end {
            return Err(Miss);
        }
        value.serialize(Ser {
            w: self.w,
            op: &NANOS,
        })?;
        self.w.pos = self.end;
        Ok(())
    }
}

/// The elements of an array or sequence.
struct Seq<'a, 't> {
    w: &'a mut W<'t>,
    /// Of a primitive: it, and the sample's length once all are written.
    packed: Option<(Primitive, usize)>,
    /// The element's op (not packed).
    body: usize,
    end: usize,
    left: usize,
}

impl Seq<'_, '_> {
    #[inline(always)]
    fn element<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Miss> {
        match self.packed {
            Some((p, _)) => value.serialize(Packed {
                buf: &mut self.w.buf,
                p,
            }),
            None => {
                self.left = self.left.checked_sub(1).ok_or(Miss)?;
                value.serialize(Ser::at(self.w, self.body)?)
            }
        }
    }

    #[inline(always)]
    fn finish(self) -> Result<(), Miss> {
        let all = match self.packed {
            Some((_, len)) => self.w.buf.len() == len,
            None => self.left == 0,
        };
        self.w.pos = self.end;
        if all {
            Ok(())
        } else {
            Err(Miss)
        }
    }
}

impl ser::SerializeSeq for Seq<'_, '_> {
    type Ok = ();
    type Error = Miss;
    #[inline(always)]
    fn serialize_element<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Miss> {
        self.element(value)
    }
    #[inline(always)]
    fn end(self) -> Result<(), Miss> {
        self.finish()
    }
}

impl ser::SerializeTuple for Seq<'_, '_> {
    type Ok = ();
    type Error = Miss;
    #[inline(always)]
    fn serialize_element<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Miss> {
        self.element(value)
    }
    #[inline(always)]
    fn end(self) -> Result<(), Miss> {
        self.finish()
    }
}

impl ser::SerializeTupleStruct for Seq<'_, '_> {
    type Ok = ();
    type Error = Miss;
    #[inline(always)]
    fn serialize_field<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Miss> {
        self.element(value)
    }
    #[inline(always)]
    fn end(self) -> Result<(), Miss> {
        self.finish()
    }
}

/// One element of an array of the primitive `p`, aligned already (every element is as
/// wide as the alignment it needs).
struct Packed<'a> {
    buf: &'a mut Vec<u8>,
    p: Primitive,
}

impl Packed<'_> {
    #[inline(always)]
    fn put<const N: usize>(self, ours: Primitive, bytes: [u8; N]) -> Result<(), Miss> {
        if self.p != ours {
            return Err(Miss);
        }
        self.buf.extend_from_slice(&bytes);
        Ok(())
    }
}

impl ser::Serializer for Packed<'_> {
    type Ok = ();
    type Error = Miss;
    type SerializeSeq = No;
    type SerializeTuple = No;
    type SerializeTupleStruct = No;
    type SerializeTupleVariant = No;
    type SerializeMap = No;
    type SerializeStruct = No;
    type SerializeStructVariant = No;

    miss! { char str bytes none some unit variants map }

    #[inline(always)]
    fn serialize_bool(self, v: bool) -> Result<(), Miss> {
        self.put(Primitive::Bool, [u8::from(v)])
    }
    #[inline(always)]
    fn serialize_i8(self, v: i8) -> Result<(), Miss> {
        self.put(Primitive::Int8, v.to_le_bytes())
    }
    #[inline(always)]
    fn serialize_i16(self, v: i16) -> Result<(), Miss> {
        self.put(Primitive::Int16, v.to_le_bytes())
    }
    #[inline(always)]
    fn serialize_i32(self, v: i32) -> Result<(), Miss> {
        self.put(Primitive::Int32, v.to_le_bytes())
    }
    #[inline(always)]
    fn serialize_i64(self, v: i64) -> Result<(), Miss> {
        self.put(Primitive::Int64, v.to_le_bytes())
    }
    #[inline(always)]
    fn serialize_u8(self, v: u8) -> Result<(), Miss> {
        self.put(Primitive::UInt8, [v])
    }
    #[inline(always)]
    fn serialize_u16(self, v: u16) -> Result<(), Miss> {
        self.put(Primitive::UInt16, v.to_le_bytes())
    }
    #[inline(always)]
    fn serialize_u32(self, v: u32) -> Result<(), Miss> {
        self.put(Primitive::UInt32, v.to_le_bytes())
    }
    #[inline(always)]
    fn serialize_u64(self, v: u64) -> Result<(), Miss> {
        self.put(Primitive::UInt64, v.to_le_bytes())
    }
    #[inline(always)]
    fn serialize_f32(self, v: f32) -> Result<(), Miss> {
        self.put(Primitive::Float32, v.to_le_bytes())
    }
    #[inline(always)]
    fn serialize_f64(self, v: f64) -> Result<(), Miss> {
        self.put(Primitive::Float64, v.to_le_bytes())
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
