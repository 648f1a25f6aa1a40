//! The serde `Deserializer` reading a port's value from CDR (see the module
//! documentation). Every length is checked against the bytes left before anything is
//! allocated (`wire.rs`).

use super::plan::{Builtin, Elem, Node, Plan, Slot};
use super::prim::PackedDe;
use super::{Expect, Fail, UINT32};
use crate::cdr::Reader;
use crate::def::{Arity, Field, Primitive};
use crate::wire::{is_bytes, In};
use serde::de::{self, DeserializeSeed, Deserializer as _, SeqAccess, Visitor};

/// The sample being read.
pub(super) struct R<'p, 'd> {
    pub plan: &'p Plan<'p>,
    pub input: In<'d>,
}

impl R<'_, '_> {
    /// Reads past `field` (checking it as the dynamic codec does).
    pub fn skip(&mut self, field: &Field) -> Result<(), Fail> {
        let mut reader = Reader {
            registry: self.plan.reg,
            input: self.input.clone(),
            path: vec![field.name.clone()],
        };
        reader.field(field, 0)?;
        self.input = reader.input;
        Ok(())
    }
}

/// Deserializes one value where the definition expects `expect`.
pub(super) struct De<'a, 'p, 'd> {
    r: &'a mut R<'p, 'd>,
    expect: Expect<'p>,
}

impl<'a, 'p, 'd> De<'a, 'p, 'd> {
    #[inline]
    pub(super) fn new(r: &'a mut R<'p, 'd>, expect: Expect<'p>) -> Self {
        De { r, expect }
    }

    #[cold]
    fn mismatch(&self, ours: &str) -> Fail {
        Fail::new(format!(
            "the port's type has {ours} where the message has {}",
            self.expect.describe(self.r.plan)
        ))
    }

    #[cold]
    fn not_struct(&self, name: &str) -> Fail {
        self.mismatch(&format!("a `{name}`"))
    }

    /// The primitive `p`, aligned.
    #[inline]
    fn primitive<'de, V: Visitor<'de>>(self, p: Primitive, v: V) -> Result<V::Value, Fail> {
        PackedDe {
            bytes: &mut self.r.input.aligned(p.size())?,
            p,
        }
        .deserialize_any(v)
    }

    /// One value (a wrapper's field if the message is a wrapper).
    #[inline]
    fn scalar<'de, V: Visitor<'de>>(self, v: V) -> Result<V::Value, Fail> {
        match self.expect {
            Expect::Elem(&Elem::Prim(p)) => self.primitive(p, v),
            Expect::Elem(&Elem::Str(bound)) => v.visit_str(self.r.input.string(bound)?),
            _ => self.scalar_slow(v),
        }
    }

    fn scalar_slow<'de, V: Visitor<'de>>(self, v: V) -> Result<V::Value, Fail> {
        let expect = self.expect.unwrap(self.r.plan)?;
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
            Expect::Elem(_) => De::new(self.r, expect).any(v),
            _ => Err(self.mismatch("one value")),
        }
    }

    /// Whatever the definition says is here.
    fn any<'de, V: Visitor<'de>>(self, v: V) -> Result<V::Value, Fail> {
        match self.expect.resolve(self.r.plan) {
            Expect::Elem(&Elem::Prim(p)) => self.primitive(p, v),
            Expect::Elem(&Elem::Str(bound)) => {
                v.visit_string(self.r.input.string(bound)?.to_string())
            }
            Expect::Message(node) => self.message(node, None, v),
            Expect::Field(slot) => self.elements(slot, None, v),
            _ => Err(self.mismatch("a value of unknown shape")),
        }
    }

    /// The fields of the message `node` as a serde sequence, for a struct of the fields
    /// `ours` (the message's own if `None`).
    #[inline]
    fn message<'de, V: Visitor<'de>>(
        self,
        node: &'p Node<'p>,
        ours: Option<&'static [&'static str]>,
        v: V,
    ) -> Result<V::Value, Fail> {
        if let Some(ours) = ours.filter(|ours| !node.named(ours)) {
            return Err(other_fields(ours, node));
        }
        if node.slots.is_empty() {
            self.r.input.take(1)?;
        }
        v.visit_seq(Fields {
            r: self.r,
            slots: &node.slots,
            next: 0,
        })
    }

    /// The elements of an array or sequence field; `want`: the length of a Rust array.
    fn elements<'de, V: Visitor<'de>>(
        self,
        slot: &'p Slot<'p>,
        want: Option<usize>,
        v: V,
    ) -> Result<V::Value, Fail> {
        let len = (self.r.input).elements(slot.arity, &slot.field.ty.base)?;
        if want.is_some_and(|n| n != len) {
            return Err(Fail::new(format!(
                "the sample has {len} elements, the port's array {}",
                want.unwrap_or(0)
            )));
        }
        // An array of a primitive: aligned once, its bytes taken whole (the length
        // fits in what is left: `In::elements`).
        let (packed, bytes) = match slot.elem {
            Elem::Prim(p) if len > 0 => {
                self.r.input.align(p.size())?;
                (Some(p), self.r.input.take(len * p.size())?)
            }
            _ => (None, &[][..]),
        };
        v.visit_seq(Elements {
            r: self.r,
            element: Expect::Elem(&slot.elem),
            packed,
            bytes,
            len,
            next: 0,
        })
    }

    fn sequence<'de, V: Visitor<'de>>(self, want: Option<usize>, v: V) -> Result<V::Value, Fail> {
        match self.expect.unwrap(self.r.plan)? {
            Expect::Field(slot) if slot.arity != Arity::Single => self.elements(slot, want, v),
            _ => Err(self.mismatch("an array")),
        }
    }
}

#[cold]
fn other_fields(ours: &[&str], node: &Node<'_>) -> Fail {
    Fail::new(format!(
        "the port's type has the fields ({}), `{}` has ({})",
        ours.join(", "),
        node.message.name,
        node.names().join(", ")
    ))
}

macro_rules! scalars {
    ($($name:ident)*) => {
        $(#[inline]
        fn $name<V: Visitor<'de>>(self, v: V) -> Result<V::Value, Fail> {
            self.scalar(v)
        })*
    };
}

macro_rules! exact {
    ($($name:ident $p:ident $visit:ident $t:ty),*) => {
        $(#[inline]
        fn $name<V: Visitor<'de>>(self, v: V) -> Result<V::Value, Fail> {
            // The message's primitive is the port's (the case that runs).
            if let Expect::Elem(Elem::Prim(Primitive::$p)) = self.expect {
                return v.$visit(<$t>::from_le_bytes(self.r.input.get()?));
            }
            self.scalar(v)
        })*
    };
}

impl<'de> de::Deserializer<'de> for De<'_, '_, '_> {
    type Error = Fail;

    scalars! { deserialize_bool deserialize_str deserialize_string }

    exact! {
        deserialize_i8 Int8 visit_i8 i8, deserialize_i16 Int16 visit_i16 i16,
        deserialize_i32 Int32 visit_i32 i32, deserialize_i64 Int64 visit_i64 i64,
        deserialize_u8 UInt8 visit_u8 u8, deserialize_u16 UInt16 visit_u16 u16,
        deserialize_u32 UInt32 visit_u32 u32, deserialize_u64 UInt64 visit_u64 u64,
        deserialize_f32 Float32 visit_f32 f32, deserialize_f64 Float64 visit_f64 f64
    }

    fn deserialize_any<V: Visitor<'de>>(self, v: V) -> Result<V::Value, Fail> {
        self.any(v)
    }
    fn deserialize_char<V: Visitor<'de>>(self, _: V) -> Result<V::Value, Fail> {
        Err(self.mismatch("a char"))
    }
    fn deserialize_bytes<V: Visitor<'de>>(self, v: V) -> Result<V::Value, Fail> {
        match self.expect.unwrap(self.r.plan)? {
            Expect::Field(slot) if slot.arity != Arity::Single && is_bytes(&slot.field.ty.base) => {
                let len = (self.r.input).elements(slot.arity, &slot.field.ty.base)?;
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
        match self.expect.resolve(self.r.plan) {
            Expect::Message(node) if node.slots.is_empty() => {
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
    #[inline]
    fn deserialize_struct<V: Visitor<'de>>(
        self,
        name: &'static str,
        fields: &'static [&'static str],
        v: V,
    ) -> Result<V::Value, Fail> {
        let Expect::Message(node) = self.expect.resolve(self.r.plan) else {
            return Err(self.not_struct(name));
        };
        match (node.builtin, name, fields) {
            (Builtin::Time, "Timestamp", ["nanos"]) => v.visit_seq(Special {
                r: self.r,
                items: &TIME,
            }),
            (Builtin::Duration, "Duration", ["secs", "nanos"]) => v.visit_seq(Special {
                r: self.r,
                items: &DURATION,
            }),
            _ => self.message(node, Some(fields), v),
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
struct Fields<'a, 'p, 'd> {
    r: &'a mut R<'p, 'd>,
    slots: &'p [Slot<'p>],
    next: usize,
}

impl<'de> SeqAccess<'de> for Fields<'_, '_, '_> {
    type Error = Fail;
    #[inline]
    fn next_element_seed<T: DeserializeSeed<'de>>(
        &mut self,
        seed: T,
    ) -> Result<Option<T::Value>, Fail> {
        let Some(slot) = self.slots.get(self.next) else {
            return Ok(None);
        };
        self.next += 1;
        match seed.deserialize(De::new(self.r, Expect::of(slot))) {
            Ok(value) => Ok(Some(value)),
            Err(e) => Err(e.within(slot.name)),
        }
    }
    fn size_hint(&self) -> Option<usize> {
        Some(self.slots.len() - self.next)
    }
}

/// An array's or sequence's elements.
struct Elements<'a, 'p, 'd> {
    r: &'a mut R<'p, 'd>,
    element: Expect<'p>,
    /// The primitive of an array of one, and the array's bytes (see `prim.rs`).
    packed: Option<Primitive>,
    bytes: &'d [u8],
    len: usize,
    next: usize,
}

impl<'de> SeqAccess<'de> for Elements<'_, '_, '_> {
    type Error = Fail;
    #[inline]
    fn next_element_seed<T: DeserializeSeed<'de>>(
        &mut self,
        seed: T,
    ) -> Result<Option<T::Value>, Fail> {
        if self.next == self.len {
            return Ok(None);
        }
        self.next += 1;
        let value = match self.packed {
            Some(p) => seed.deserialize(PackedDe {
                bytes: &mut self.bytes,
                p,
            }),
            None => seed.deserialize(De::new(self.r, self.element)),
        };
        match value {
            Ok(value) => Ok(Some(value)),
            Err(e) => Err(e.at(self.next - 1)),
        }
    }
    fn size_hint(&self) -> Option<usize> {
        Some(self.len - self.next)
    }
}

/// `Timestamp`'s one field.
static TIME: [Expect<'static>; 1] = [Expect::TimeNanos];
/// `std::time::Duration`'s two fields.
static DURATION: [Expect<'static>; 2] = [Expect::DurationSecs, Expect::Elem(&UINT32)];

/// The fields of `Timestamp` or `Duration` read from their builtin message.
struct Special<'a, 'p, 'd> {
    r: &'a mut R<'p, 'd>,
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
