//! The serde `Deserializer` reading a port's value from CDR (see the module
//! documentation). Every length is checked against the bytes left before anything is
//! allocated (`wire.rs`).

use super::{builtin, Expect, Fail, Look, UINT32};
use crate::cdr::Reader;
use crate::def::{Arity, BaseType, Field, FieldType, Message, Primitive};
use crate::wire::{is_bytes, In};
use serde::de::{self, DeserializeSeed, SeqAccess, Visitor};

/// The sample being read and where in the message it is.
pub(super) struct R<'r, 'd> {
    pub reg: Look<'r>,
    pub input: In<'d>,
    /// The field path, for errors.
    pub path: Vec<&'r str>,
}

impl<'r> R<'r, '_> {
    /// Reads past `field` (checking it as the dynamic codec does).
    pub fn skip(&mut self, field: &'r Field) -> Result<(), Fail> {
        let mut reader = Reader {
            registry: self.reg.reg,
            input: self.input.clone(),
            path: vec![field.name.clone()],
        };
        reader.field(field, 0)?;
        self.input = reader.input;
        Ok(())
    }
}

/// Deserializes one value where the definition expects `expect`.
pub(super) struct De<'a, 'r, 'd> {
    r: &'a mut R<'r, 'd>,
    expect: Expect<'r>,
}

impl<'a, 'r, 'd> De<'a, 'r, 'd> {
    pub(super) fn new(r: &'a mut R<'r, 'd>, expect: Expect<'r>) -> Self {
        De { r, expect }
    }

    fn mismatch(&self, ours: &str) -> Fail {
        Fail(format!(
            "the port's type has {ours} where the message has {}",
            self.expect.describe()
        ))
    }

    fn primitive<'de, V: Visitor<'de>>(self, p: Primitive, v: V) -> Result<V::Value, Fail> {
        use Primitive::*;
        let r = &mut self.r.input;
        match p {
            Bool => v.visit_bool(r.bool()?),
            Byte | Char | UInt8 => v.visit_u8(r.get::<1>()?[0]),
            Int8 => v.visit_i8(i8::from_le_bytes(r.get()?)),
            Int16 => v.visit_i16(i16::from_le_bytes(r.get()?)),
            UInt16 => v.visit_u16(u16::from_le_bytes(r.get()?)),
            Int32 => v.visit_i32(i32::from_le_bytes(r.get()?)),
            UInt32 => v.visit_u32(u32::from_le_bytes(r.get()?)),
            Int64 => v.visit_i64(i64::from_le_bytes(r.get()?)),
            UInt64 => v.visit_u64(u64::from_le_bytes(r.get()?)),
            Float32 => v.visit_f32(f32::from_le_bytes(r.get()?)),
            Float64 => v.visit_f64(f64::from_le_bytes(r.get()?)),
        }
    }

    /// One value (a wrapper's field if the message is a wrapper).
    #[inline]
    fn scalar<'de, V: Visitor<'de>>(self, v: V) -> Result<V::Value, Fail> {
        if let Expect::Base(BaseType::Primitive(p)) = self.expect {
            return self.primitive(*p, v);
        }
        let expect = self.expect.unwrap(self.r.reg)?;
        match expect {
            Expect::TimeNanos => {
                let sec = i32::from_le_bytes(self.r.input.get()?);
                let nanosec = u32::from_le_bytes(self.r.input.get()?);
                v.visit_i64(i64::from(sec) * 1_000_000_000 + i64::from(nanosec))
            }
            Expect::DurationSecs => {
                let sec = i32::from_le_bytes(self.r.input.get()?);
                let secs = u64::try_from(sec)
                    .map_err(|_| "a negative duration (sec < 0) in a non-negative one")?;
                v.visit_u64(secs)
            }
            Expect::Base(_) => De::new(self.r, expect).any(v),
            _ => Err(self.mismatch("one value")),
        }
    }

    /// Whatever the definition says is here.
    fn any<'de, V: Visitor<'de>>(self, v: V) -> Result<V::Value, Fail> {
        match self.expect.resolve(self.r.reg)? {
            Expect::Base(BaseType::Primitive(p)) => self.primitive(*p, v),
            Expect::Base(BaseType::String { bound }) => {
                v.visit_string(self.r.input.string(*bound)?.to_string())
            }
            Expect::Message(m) => {
                let names: Vec<&str> = m.fields.iter().map(|f| f.name.as_str()).collect();
                self.message(m, &names, v)
            }
            Expect::Field(ty) => self.elements(ty, None, v),
            _ => Err(self.mismatch("a value of unknown shape")),
        }
    }

    /// The fields of the message `m` as a serde sequence, for a struct of the fields
    /// `ours`.
    fn message<'de, V: Visitor<'de>>(
        self,
        m: &'r Message,
        ours: &[&str],
        v: V,
    ) -> Result<V::Value, Fail> {
        let theirs: Vec<&str> = m.fields.iter().map(|f| f.name.as_str()).collect();
        if ours != theirs.as_slice() {
            return Err(Fail(format!(
                "the port's type has the fields ({}), `{}` has ({})",
                ours.join(", "),
                m.name,
                theirs.join(", ")
            )));
        }
        if m.fields.is_empty() {
            self.r.input.take(1)?;
        }
        v.visit_seq(Fields {
            r: self.r,
            fields: &m.fields,
            next: 0,
        })
    }

    /// The elements of an array or sequence field; `want`: the length of a Rust array.
    fn elements<'de, V: Visitor<'de>>(
        self,
        ty: &'r FieldType,
        want: Option<usize>,
        v: V,
    ) -> Result<V::Value, Fail> {
        let len = self.r.input.elements(ty.arity, &ty.base)?;
        if want.is_some_and(|n| n != len) {
            return Err(Fail(format!(
                "the sample has {len} elements, the port's array {}",
                want.unwrap_or(0)
            )));
        }
        v.visit_seq(Elements {
            r: self.r,
            base: &ty.base,
            left: len,
        })
    }

    fn sequence<'de, V: Visitor<'de>>(self, want: Option<usize>, v: V) -> Result<V::Value, Fail> {
        match self.expect.unwrap(self.r.reg)? {
            Expect::Field(ty) if ty.arity != Arity::Single => self.elements(ty, want, v),
            _ => Err(self.mismatch("an array")),
        }
    }
}

macro_rules! scalars {
    ($($name:ident)*) => {
        $(fn $name<V: Visitor<'de>>(self, v: V) -> Result<V::Value, Fail> {
            self.scalar(v)
        })*
    };
}

impl<'de> de::Deserializer<'de> for De<'_, '_, '_> {
    type Error = Fail;

    scalars! {
        deserialize_bool deserialize_i8 deserialize_i16 deserialize_i32 deserialize_i64
        deserialize_u8 deserialize_u16 deserialize_u32 deserialize_u64 deserialize_f32
        deserialize_f64 deserialize_str deserialize_string
    }

    fn deserialize_any<V: Visitor<'de>>(self, v: V) -> Result<V::Value, Fail> {
        self.any(v)
    }
    fn deserialize_char<V: Visitor<'de>>(self, _: V) -> Result<V::Value, Fail> {
        Err(self.mismatch("a char"))
    }
    fn deserialize_bytes<V: Visitor<'de>>(self, v: V) -> Result<V::Value, Fail> {
        match self.expect.unwrap(self.r.reg)? {
            Expect::Field(ty) if ty.arity != Arity::Single && is_bytes(&ty.base) => {
                let len = self.r.input.elements(ty.arity, &ty.base)?;
                v.visit_bytes(self.r.input.take(len)?)
            }
            _ => Err(self.mismatch("bytes")),
        }
    }
    fn deserialize_byte_buf<V: Visitor<'de>>(self, v: V) -> Result<V::Value, Fail> {
        self.deserialize_bytes(v)
    }
    fn deserialize_option<V: Visitor<'de>>(self, _: V) -> Result<V::Value, Fail> {
        Err(self.mismatch("an optional value"))
    }
    fn deserialize_unit<V: Visitor<'de>>(self, v: V) -> Result<V::Value, Fail> {
        match self.expect.resolve(self.r.reg)? {
            Expect::Message(m) if m.fields.is_empty() => {
                self.r.input.take(1)?;
                v.visit_unit()
            }
            _ => Err(self.mismatch("no value")),
        }
    }
    fn deserialize_unit_struct<V: Visitor<'de>>(
        self,
        _: &'static str,
        v: V,
    ) -> Result<V::Value, Fail> {
        self.deserialize_unit(v)
    }
    fn deserialize_newtype_struct<V: Visitor<'de>>(
        self,
        _: &'static str,
        v: V,
    ) -> Result<V::Value, Fail> {
        v.visit_newtype_struct(self)
    }
    fn deserialize_seq<V: Visitor<'de>>(self, v: V) -> Result<V::Value, Fail> {
        self.sequence(None, v)
    }
    fn deserialize_tuple<V: Visitor<'de>>(self, len: usize, v: V) -> Result<V::Value, Fail> {
        self.sequence(Some(len), v)
    }
    fn deserialize_tuple_struct<V: Visitor<'de>>(
        self,
        _: &'static str,
        len: usize,
        v: V,
    ) -> Result<V::Value, Fail> {
        self.sequence(Some(len), v)
    }
    fn deserialize_map<V: Visitor<'de>>(self, _: V) -> Result<V::Value, Fail> {
        Err(self.mismatch("a map"))
    }
    fn deserialize_struct<V: Visitor<'de>>(
        self,
        name: &'static str,
        fields: &'static [&'static str],
        v: V,
    ) -> Result<V::Value, Fail> {
        let Expect::Message(m) = self.expect.resolve(self.r.reg)? else {
            return Err(self.mismatch(&format!("a `{name}`")));
        };
        match (name, fields) {
            ("Timestamp", ["nanos"]) if builtin(m, "Time") => v.visit_seq(Special {
                r: self.r,
                items: &TIME,
            }),
            ("Duration", ["secs", "nanos"]) if builtin(m, "Duration") => v.visit_seq(Special {
                r: self.r,
                items: &DURATION,
            }),
            _ => self.message(m, fields, v),
        }
    }
    fn deserialize_enum<V: Visitor<'de>>(
        self,
        name: &'static str,
        _: &'static [&'static str],
        _: V,
    ) -> Result<V::Value, Fail> {
        Err(self.mismatch(&format!("the enum `{name}`")))
    }
    fn deserialize_identifier<V: Visitor<'de>>(self, _: V) -> Result<V::Value, Fail> {
        Err(self.mismatch("a field name"))
    }
    fn deserialize_ignored_any<V: Visitor<'de>>(self, v: V) -> Result<V::Value, Fail> {
        self.any(de::IgnoredAny).and_then(|_| v.visit_unit())
    }
    fn is_human_readable(&self) -> bool {
        false
    }
}

/// A message's fields, in order.
struct Fields<'a, 'r, 'd> {
    r: &'a mut R<'r, 'd>,
    fields: &'r [Field],
    next: usize,
}

impl<'de> SeqAccess<'de> for Fields<'_, '_, '_> {
    type Error = Fail;
    fn next_element_seed<T: DeserializeSeed<'de>>(
        &mut self,
        seed: T,
    ) -> Result<Option<T::Value>, Fail> {
        let Some(f) = self.fields.get(self.next) else {
            return Ok(None);
        };
        self.next += 1;
        self.r.path.push(&f.name);
        let value = seed.deserialize(De::new(self.r, Expect::Field(&f.ty)))?;
        self.r.path.pop();
        Ok(Some(value))
    }
    fn size_hint(&self) -> Option<usize> {
        Some(self.fields.len() - self.next)
    }
}

/// An array's or sequence's elements.
struct Elements<'a, 'r, 'd> {
    r: &'a mut R<'r, 'd>,
    base: &'r BaseType,
    left: usize,
}

impl<'de> SeqAccess<'de> for Elements<'_, '_, '_> {
    type Error = Fail;
    fn next_element_seed<T: DeserializeSeed<'de>>(
        &mut self,
        seed: T,
    ) -> Result<Option<T::Value>, Fail> {
        if self.left == 0 {
            return Ok(None);
        }
        self.left -= 1;
        seed.deserialize(De::new(self.r, Expect::Base(self.base)))
            .map(Some)
    }
    fn size_hint(&self) -> Option<usize> {
        Some(self.left)
    }
}

/// `Timestamp`'s one field.
static TIME: [Expect<'static>; 1] = [Expect::TimeNanos];
/// `std::time::Duration`'s two fields.
static DURATION: [Expect<'static>; 2] = [Expect::DurationSecs, Expect::Base(&UINT32)];

/// The fields of `Timestamp` or `Duration` read from their builtin message.
struct Special<'a, 'r, 'd> {
    r: &'a mut R<'r, 'd>,
    items: &'static [Expect<'static>],
}

impl<'de> SeqAccess<'de> for Special<'_, '_, '_> {
    type Error = Fail;
    fn next_element_seed<T: DeserializeSeed<'de>>(
        &mut self,
        seed: T,
    ) -> Result<Option<T::Value>, Fail> {
        let Some((first, rest)) = self.items.split_first() else {
            return Ok(None);
        };
        self.items = rest;
        seed.deserialize(De::new(self.r, *first)).map(Some)
    }
}
