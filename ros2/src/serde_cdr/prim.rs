//! The elements of an array or sequence of a primitive (a laser scan's ranges, a
//! covariance): aligned once before the first (each element is as wide as the alignment
//! it needs, so the others follow back to back), then written and read with no more
//! than the check that the port's element type is the message's.

use super::{same, Fail};
use crate::def::Primitive;
use crate::wire::Out;
use serde::de::{self, Visitor};
use serde::ser::{self, Impossible, Serialize};

/// Writes one element of an array of `p`.
pub(super) struct PackedSer<'a> {
    pub out: &'a mut Out,
    pub p: Primitive,
}

impl PackedSer<'_> {
    #[inline(always)]
    fn put<const N: usize>(self, ours: Primitive, bytes: [u8; N]) -> Result<(), Fail> {
        if same(ours, self.p) {
            self.out.buf.extend_from_slice(&bytes);
            Ok(())
        } else {
            Err(self.mismatch(ours.msg_name()))
        }
    }

    #[cold]
    fn mismatch(&self, ours: &str) -> Fail {
        Fail::new(format!(
            "the value has {ours} where the message has {}",
            self.p.msg_name()
        ))
    }
}

type No = Impossible<(), Fail>;

impl ser::Serializer for PackedSer<'_> {
    type Ok = ();
    type Error = Fail;
    type SerializeSeq = No;
    type SerializeTuple = No;
    type SerializeTupleStruct = No;
    type SerializeTupleVariant = No;
    type SerializeMap = No;
    type SerializeStruct = No;
    type SerializeStructVariant = No;

    #[inline(always)]
    fn serialize_bool(self, v: bool) -> Result<(), Fail> {
        self.put(Primitive::Bool, [u8::from(v)])
    }
    #[inline(always)]
    fn serialize_i8(self, v: i8) -> Result<(), Fail> {
        self.put(Primitive::Int8, v.to_le_bytes())
    }
    #[inline(always)]
    fn serialize_i16(self, v: i16) -> Result<(), Fail> {
        self.put(Primitive::Int16, v.to_le_bytes())
    }
    #[inline(always)]
    fn serialize_i32(self, v: i32) -> Result<(), Fail> {
        self.put(Primitive::Int32, v.to_le_bytes())
    }
    #[inline(always)]
    fn serialize_i64(self, v: i64) -> Result<(), Fail> {
        self.put(Primitive::Int64, v.to_le_bytes())
    }
    #[inline(always)]
    fn serialize_u8(self, v: u8) -> Result<(), Fail> {
        self.put(Primitive::UInt8, [v])
    }
    #[inline(always)]
    fn serialize_u16(self, v: u16) -> Result<(), Fail> {
        self.put(Primitive::UInt16, v.to_le_bytes())
    }
    #[inline(always)]
    fn serialize_u32(self, v: u32) -> Result<(), Fail> {
        self.put(Primitive::UInt32, v.to_le_bytes())
    }
    #[inline(always)]
    fn serialize_u64(self, v: u64) -> Result<(), Fail> {
        self.put(Primitive::UInt64, v.to_le_bytes())
    }
    #[inline(always)]
    fn serialize_f32(self, v: f32) -> Result<(), Fail> {
        self.put(Primitive::Float32, v.to_le_bytes())
    }
    #[inline(always)]
    fn serialize_f64(self, v: f64) -> Result<(), Fail> {
        self.put(Primitive::Float64, v.to_le_bytes())
    }
    fn serialize_char(self, _: char) -> Result<(), Fail> {
        Err(self.mismatch("a char"))
    }
    fn serialize_str(self, _: &str) -> Result<(), Fail> {
        Err(self.mismatch("a string"))
    }
    fn serialize_bytes(self, _: &[u8]) -> Result<(), Fail> {
        Err(self.mismatch("bytes"))
    }
    fn serialize_none(self) -> Result<(), Fail> {
        Err(self.mismatch("an optional value"))
    }
    fn serialize_some<T: Serialize + ?Sized>(self, _: &T) -> Result<(), Fail> {
        Err(self.mismatch("an optional value"))
    }
    fn serialize_unit(self) -> Result<(), Fail> {
        Err(self.mismatch("no value"))
    }
    fn serialize_unit_struct(self, _: &'static str) -> Result<(), Fail> {
        Err(self.mismatch("no value"))
    }
    fn serialize_unit_variant(self, _: &'static str, _: u32, v: &'static str) -> Result<(), Fail> {
        Err(self.mismatch(&format!("the enum value `{v}`")))
    }
    #[inline(always)]
    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        value: &T,
    ) -> Result<(), Fail> {
        value.serialize(self)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: u32,
        v: &'static str,
        _: &T,
    ) -> Result<(), Fail> {
        Err(self.mismatch(&format!("the enum value `{v}`")))
    }
    fn serialize_seq(self, _: Option<usize>) -> Result<No, Fail> {
        Err(self.mismatch("an array"))
    }
    fn serialize_tuple(self, _: usize) -> Result<No, Fail> {
        Err(self.mismatch("an array"))
    }
    fn serialize_tuple_struct(self, name: &'static str, _: usize) -> Result<No, Fail> {
        Err(self.mismatch(&format!("a `{name}`")))
    }
    fn serialize_tuple_variant(
        self,
        _: &'static str,
        _: u32,
        v: &'static str,
        _: usize,
    ) -> Result<No, Fail> {
        Err(self.mismatch(&format!("the enum value `{v}`")))
    }
    fn serialize_map(self, _: Option<usize>) -> Result<No, Fail> {
        Err(self.mismatch("a map"))
    }
    fn serialize_struct(self, name: &'static str, _: usize) -> Result<No, Fail> {
        Err(self.mismatch(&format!("a `{name}`")))
    }
    fn serialize_struct_variant(
        self,
        _: &'static str,
        _: u32,
        v: &'static str,
        _: usize,
    ) -> Result<No, Fail> {
        Err(self.mismatch(&format!("the enum value `{v}`")))
    }
}

/// Reads one element of an array of `p` from the array's bytes (taken whole from the
/// sample: no bounds to keep but these), offered to the port's type as what the message
/// has (a port's `f32` element of a `float64` array is serde's type error).
pub(super) struct PackedDe<'a, 'd> {
    pub bytes: &'a mut &'d [u8],
    pub p: Primitive,
}

impl PackedDe<'_, '_> {
    #[inline(always)]
    fn next<const N: usize>(&mut self) -> Result<[u8; N], Fail> {
        match self.bytes.split_first_chunk::<N>() {
            Some((bytes, rest)) => {
                *self.bytes = rest;
                Ok(*bytes)
            }
            None => Err(Fail::new("the sample ends early")),
        }
    }

    #[inline(always)]
    fn visit<'de, V: Visitor<'de>>(mut self, v: V) -> Result<V::Value, Fail> {
        use Primitive::*;
        match self.p {
            Float32 => v.visit_f32(f32::from_le_bytes(self.next()?)),
            Float64 => v.visit_f64(f64::from_le_bytes(self.next()?)),
            Bool => match self.next::<1>()? {
                [0] => v.visit_bool(false),
                [1] => v.visit_bool(true),
                [b] => Err(Fail::new(format!("a bool is 0 or 1, the sample has {b}"))),
            },
            Byte | Char | UInt8 => v.visit_u8(self.next::<1>()?[0]),
            Int8 => v.visit_i8(i8::from_le_bytes(self.next()?)),
            Int16 => v.visit_i16(i16::from_le_bytes(self.next()?)),
            UInt16 => v.visit_u16(u16::from_le_bytes(self.next()?)),
            Int32 => v.visit_i32(i32::from_le_bytes(self.next()?)),
            UInt32 => v.visit_u32(u32::from_le_bytes(self.next()?)),
            Int64 => v.visit_i64(i64::from_le_bytes(self.next()?)),
            UInt64 => v.visit_u64(u64::from_le_bytes(self.next()?)),
        }
    }

    #[cold]
    fn mismatch(&self, ours: &str) -> Fail {
        Fail::new(format!(
            "the port's type has {ours} where the message has {}",
            self.p.msg_name()
        ))
    }
}

macro_rules! visit {
    ($($name:ident)*) => {
        $(#[inline(always)]
        fn $name<V: Visitor<'de>>(self, v: V) -> Result<V::Value, Fail> {
            self.visit(v)
        })*
    };
}

macro_rules! exact {
    ($($name:ident $p:ident $visit:ident $t:ty),*) => {
        $(#[inline(always)]
        fn $name<V: Visitor<'de>>(mut self, v: V) -> Result<V::Value, Fail> {
            if self.p == Primitive::$p {
                return v.$visit(<$t>::from_le_bytes(self.next()?));
            }
            self.visit(v)
        })*
    };
}

macro_rules! refuse {
    ($($name:ident $what:literal)*) => {
        $(fn $name<V: Visitor<'de>>(self, _: V) -> Result<V::Value, Fail> {
            Err(self.mismatch($what))
        })*
    };
}

impl<'de> de::Deserializer<'de> for PackedDe<'_, '_> {
    type Error = Fail;

    visit! {
        deserialize_any deserialize_bool deserialize_str deserialize_string
        deserialize_ignored_any
    }

    // The port's element type is the message's (the case that runs): one compare, no
    // dispatch on the message's type.
    exact! {
        deserialize_i8 Int8 visit_i8 i8, deserialize_i16 Int16 visit_i16 i16,
        deserialize_i32 Int32 visit_i32 i32, deserialize_i64 Int64 visit_i64 i64,
        deserialize_u8 UInt8 visit_u8 u8, deserialize_u16 UInt16 visit_u16 u16,
        deserialize_u32 UInt32 visit_u32 u32, deserialize_u64 UInt64 visit_u64 u64,
        deserialize_f32 Float32 visit_f32 f32, deserialize_f64 Float64 visit_f64 f64
    }

    refuse! {
        deserialize_char "a char" deserialize_bytes "bytes" deserialize_byte_buf "bytes"
        deserialize_option "an optional value" deserialize_unit "no value"
        deserialize_seq "an array" deserialize_map "a map"
        deserialize_identifier "a field name"
    }

    fn deserialize_unit_struct<V: Visitor<'de>>(
        self,
        _: &'static str,
        _: V,
    ) -> Result<V::Value, Fail> {
        Err(self.mismatch("no value"))
    }
    #[inline(always)]
    fn deserialize_newtype_struct<V: Visitor<'de>>(
        self,
        _: &'static str,
        v: V,
    ) -> Result<V::Value, Fail> {
        v.visit_newtype_struct(self)
    }
    fn deserialize_tuple<V: Visitor<'de>>(self, _: usize, _: V) -> Result<V::Value, Fail> {
        Err(self.mismatch("an array"))
    }
    fn deserialize_tuple_struct<V: Visitor<'de>>(
        self,
        name: &'static str,
        _: usize,
        _: V,
    ) -> Result<V::Value, Fail> {
        Err(self.mismatch(&format!("a `{name}`")))
    }
    fn deserialize_struct<V: Visitor<'de>>(
        self,
        name: &'static str,
        _: &'static [&'static str],
        _: V,
    ) -> Result<V::Value, Fail> {
        Err(self.mismatch(&format!("a `{name}`")))
    }
    fn deserialize_enum<V: Visitor<'de>>(
        self,
        name: &'static str,
        _: &'static [&'static str],
        _: V,
    ) -> Result<V::Value, Fail> {
        Err(self.mismatch(&format!("the enum `{name}`")))
    }
    fn is_human_readable(&self) -> bool {
        false
    }
}
