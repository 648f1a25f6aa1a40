//! Writing a value along the tape (see `mod.rs`).

use super::packed::Packed;
use super::{Kind, Miss, Op, DYNAMIC, NANOS};
use crate::def::Primitive;
use crate::wire::HEADER;
use serde::ser::{self, Impossible, Serialize};

/// What a refused compound gives (see `miss!`).
type No = Impossible<(), Miss>;

/// Writes `value`, the message of `ops`, into `buf` (cleared first, capacity kept).
/// `Ok(true)`: the trusted writer may write values of this type from now on (every Time
/// was a `Timestamp`, and only Times were; see `trusted.rs`).
pub(super) fn write<T: Serialize + ?Sized>(
    ops: &[Op<'_>],
    value: &T,
    buf: &mut Vec<u8>,
) -> Result<bool, Miss> {
    let mut w = W {
        ops,
        pos: 0,
        buf: std::mem::take(buf),
        trustable: true,
    };
    w.buf.clear();
    w.buf.extend_from_slice(&HEADER);
    let done = Ser::at(&mut w, 0).and_then(|s| value.serialize(s));
    *buf = w.buf;
    done.map(|()| w.trustable)
}

/// The sample being written and the op next on the tape.
struct W<'t> {
    ops: &'t [Op<'t>],
    pos: usize,
    buf: Vec<u8>,
    trustable: bool,
}

impl W<'_> {
    /// A primitive of `N` bytes after `pad` bytes of padding (known from the tape, or
    /// [`DYNAMIC`]: to a multiple of `N` counted from after the header).
    #[inline(always)]
    fn put<const N: usize>(&mut self, pad: u8, bytes: [u8; N]) {
        if pad != 0 {
            self.pad(pad, N);
        }
        self.buf.extend_from_slice(&bytes);
    }

    #[inline(never)]
    fn pad(&mut self, pad: u8, align: usize) {
        let pad = match pad {
            DYNAMIC => HEADER.len().wrapping_sub(self.buf.len()) & (align - 1),
            pad => pad as usize,
        };
        self.buf.resize(self.buf.len() + pad, 0);
    }

    /// The count of the sequence `op` of `len` elements, nothing for an array (whose
    /// length must be its own).
    #[inline(always)]
    fn count(&mut self, op: &Op<'_>, len: usize) -> Result<(), Miss> {
        if op.fixed {
            return if len == op.n as usize {
                Ok(())
            } else {
                Err(Miss)
            };
        }
        match u32::try_from(len) {
            Ok(len) if len <= op.n => {
                self.put(op.pad, len.to_le_bytes());
                Ok(())
            }
            _ => Err(Miss),
        }
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
        self.w.put(self.op.pad, bytes);
        Ok(())
    }

    /// An array or sequence of `len` elements.
    #[inline(always)]
    fn seq(self, len: usize) -> Result<Seq<'a, 't>, Miss> {
        let op = self.op;
        if op.kind != Kind::Seq {
            return Err(Miss);
        }
        self.w.count(op, len)?;
        let Some(p) = op.elem else {
            return Ok(Seq::Nested {
                body: self.w.pos,
                w: self.w,
                end: op.end,
                left: len,
            });
        };
        // Packed: nothing of the tape inside.
        self.w.pos = op.end;
        if len > 0 && op.pad_elem != 0 {
            self.w.pad(op.pad_elem, p.size());
        }
        Packed::new(&mut self.w.buf, p, len).map(Seq::Packed)
    }
}

/// The serializer methods of the primitives that take no special case, each giving its
/// little-endian bytes to `self.$via(primitive, bytes)` (both serializers below).
macro_rules! by_primitive {
    ($via:ident: $($name:ident $p:ident $t:ty),*) => {
        $(#[inline(always)]
        fn $name(self, v: $t) -> Result<(), Miss> {
            self.$via(Primitive::$p, v.to_le_bytes())
        })*
    };
}

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

    by_primitive! {
        prim:
        serialize_i8 Int8 i8, serialize_i16 Int16 i16, serialize_i32 Int32 i32,
        serialize_u8 UInt8 u8, serialize_u16 UInt16 u16, serialize_u32 UInt32 u32,
        serialize_u64 UInt64 u64, serialize_f32 Float32 f32, serialize_f64 Float64 f64
    }

    #[inline(always)]
    fn serialize_bool(self, v: bool) -> Result<(), Miss> {
        self.prim(Primitive::Bool, [u8::from(v)])
    }
    #[inline(always)]
    fn serialize_i64(self, v: i64) -> Result<(), Miss> {
        if self.op.kind == Kind::Nanos {
            // builtin_interfaces/msg/Time: int32 sec (floor), uint32 nanosec.
            let sec = i32::try_from(v.div_euclid(1_000_000_000)).map_err(|_| Miss)?;
            self.w.put(DYNAMIC, sec.to_le_bytes());
            self.w
                .put(0, (v.rem_euclid(1_000_000_000) as u32).to_le_bytes());
            return Ok(());
        }
        self.prim(Primitive::Int64, v.to_le_bytes())
    }
    #[inline]
    fn serialize_str(self, v: &str) -> Result<(), Miss> {
        if self.op.kind != Kind::Str || v.len() > self.op.n as usize || v.as_bytes().contains(&0) {
            return Err(Miss);
        }
        let len = u32::try_from(v.len() + 1).map_err(|_| Miss)?;
        self.w.put(self.op.pad, len.to_le_bytes());
        self.w.buf.extend_from_slice(v.as_bytes());
        self.w.buf.push(0);
        Ok(())
    }
    fn serialize_bytes(self, v: &[u8]) -> Result<(), Miss> {
        if self.op.kind != Kind::Seq || self.op.elem != Some(Primitive::UInt8) {
            return Err(Miss);
        }
        self.w.count(self.op, v.len())?;
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
        let op = self.op;
        if op.kind != Kind::Struct {
            return Err(Miss);
        }
        let timestamp = len == 1 && name == "Timestamp";
        let time = op.time && timestamp;
        if !time && len != op.n as usize {
            return Err(Miss);
        }
        if op.time != timestamp {
            // A Time as its fields, or a `Timestamp` that is not a Time.
            self.w.trustable = false;
        }
        if op.n == 0 {
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
    #[inline]
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
enum Seq<'a, 't> {
    /// Of a primitive (see `packed.rs`).
    Packed(Packed<'a>),
    /// Of anything else: each element the op `body`, the tape's ops of the sequence
    /// ending at `end`, `left` elements still to write.
    Nested {
        w: &'a mut W<'t>,
        body: usize,
        end: usize,
        left: usize,
    },
    /// An element was not what the sequence holds, or one too many: a miss at the end.
    Spoilt,
}

impl<'a, 't> Seq<'a, 't> {
    #[inline(always)]
    fn element<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Miss> {
        let done = value.serialize(Item { seq: self });
        if done.is_err() {
            *self = Seq::Spoilt;
        }
        done
    }

    /// The next element's serializer (not packed).
    #[inline]
    fn next(&mut self) -> Result<Ser<'_, 't>, Miss> {
        let Seq::Nested { w, body, left, .. } = self else {
            return Err(Miss);
        };
        *left = left.checked_sub(1).ok_or(Miss)?;
        Ser::at(w, *body)
    }

    #[inline(always)]
    fn finish(self) -> Result<(), Miss> {
        let all = match self {
            Seq::Packed(packed) => packed.full(),
            Seq::Nested { w, end, left, .. } => {
                w.pos = end;
                left == 0
            }
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

/// One element of an array: of a primitive, written packed (aligned already: every
/// element is as wide as the alignment it needs); of anything else, the element's op.
struct Item<'s, 'a, 't> {
    seq: &'s mut Seq<'a, 't>,
}

impl Item<'_, '_, '_> {
    #[inline(always)]
    fn put<const N: usize>(self, ours: Primitive, bytes: [u8; N]) -> Result<(), Miss> {
        match self.seq {
            Seq::Packed(packed) => packed.fill(ours, bytes),
            _ => Err(Miss),
        }
    }
}

impl<'s, 't> ser::Serializer for Item<'s, '_, 't> {
    type Ok = ();
    type Error = Miss;
    type SerializeSeq = Seq<'s, 't>;
    type SerializeTuple = Seq<'s, 't>;
    type SerializeTupleStruct = Seq<'s, 't>;
    type SerializeTupleVariant = No;
    type SerializeMap = No;
    type SerializeStruct = Struct<'s, 't>;
    type SerializeStructVariant = No;

    miss! { char none some unit variants map }

    by_primitive! {
        put:
        serialize_i8 Int8 i8, serialize_i16 Int16 i16, serialize_i32 Int32 i32,
        serialize_i64 Int64 i64, serialize_u8 UInt8 u8, serialize_u16 UInt16 u16,
        serialize_u32 UInt32 u32, serialize_u64 UInt64 u64, serialize_f32 Float32 f32,
        serialize_f64 Float64 f64
    }

    #[inline(always)]
    fn serialize_bool(self, v: bool) -> Result<(), Miss> {
        self.put(Primitive::Bool, [u8::from(v)])
    }
    #[inline(always)]
    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        value: &T,
    ) -> Result<(), Miss> {
        value.serialize(self)
    }
    fn serialize_str(self, v: &str) -> Result<(), Miss> {
        self.seq.next()?.serialize_str(v)
    }
    fn serialize_bytes(self, v: &[u8]) -> Result<(), Miss> {
        self.seq.next()?.serialize_bytes(v)
    }
    fn serialize_seq(self, len: Option<usize>) -> Result<Seq<'s, 't>, Miss> {
        self.seq.next()?.serialize_seq(len)
    }
    fn serialize_tuple(self, len: usize) -> Result<Seq<'s, 't>, Miss> {
        self.seq.next()?.serialize_tuple(len)
    }
    fn serialize_tuple_struct(self, name: &'static str, len: usize) -> Result<Seq<'s, 't>, Miss> {
        self.seq.next()?.serialize_tuple_struct(name, len)
    }
    #[inline]
    fn serialize_struct(self, name: &'static str, len: usize) -> Result<Struct<'s, 't>, Miss> {
        self.seq.next()?.serialize_struct(name, len)
    }
}
