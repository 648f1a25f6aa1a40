//! The serde `Serializer` writing a port's value as CDR (see the module documentation).

use super::plan::{Builtin, Elem, Node, Plan};
use super::prim::PackedSer;
use super::{same, Expect, Fail, UINT32};
use crate::def::{Arity, Primitive};
use crate::wire::{is_bytes, Out};
use serde::ser::{self, Impossible, Serialize};

/// The sample being written.
pub(super) struct W<'p> {
    pub plan: &'p Plan<'p>,
    pub out: Out,
}

/// Serializes one value where the definition expects `expect`.
pub(super) struct Ser<'a, 'p> {
    w: &'a mut W<'p>,
    expect: Expect<'p>,
}

impl<'a, 'p> Ser<'a, 'p> {
    #[inline]
    pub(super) fn new(w: &'a mut W<'p>, expect: Expect<'p>) -> Self {
        Ser { w, expect }
    }

    #[cold]
    fn mismatch(&self, ours: &str) -> Fail {
        Fail::new(format!(
            "the value has {ours} where the message has {}",
            self.expect.describe(self.w.plan)
        ))
    }

    #[cold]
    fn not_struct(&self, name: &str) -> Fail {
        self.mismatch(&format!("a `{name}`"))
    }

    /// A primitive of the port's type `ours`, written if the message has the same
    /// primitive here.
    #[inline(always)]
    fn primitive<const N: usize>(self, ours: Primitive, bytes: [u8; N]) -> Result<(), Fail> {
        match self.expect {
            Expect::Elem(&Elem::Prim(p)) if same(ours, p) => {
                self.w.out.put(bytes);
                Ok(())
            }
            _ => self.primitive_slow(ours, bytes),
        }
    }

    /// [`Self::primitive`] where the message may wrap it.
    fn primitive_slow<const N: usize>(self, ours: Primitive, bytes: [u8; N]) -> Result<(), Fail> {
        match self.expect.unwrap(self.w.plan)? {
            Expect::Elem(&Elem::Prim(p)) if same(ours, p) => {
                self.w.out.put(bytes);
                Ok(())
            }
            _ => Err(self.mismatch(ours.msg_name())),
        }
    }

    /// The sequence or array field a serde sequence of `len` elements is.
    fn sequence(self, len: Option<usize>) -> Result<Seq<'a, 'p>, Fail> {
        let Expect::Field(slot) = self.expect.unwrap(self.w.plan)? else {
            return Err(self.mismatch("an array"));
        };
        let len = len.ok_or("a sequence of unknown length")?;
        self.w.out.arity(slot.arity, len)?;
        let packed = match slot.elem {
            Elem::Prim(p) => {
                if len > 0 {
                    self.w.out.align(p.size());
                    self.w.out.buf.reserve(len * p.size());
                }
                Some(p)
            }
            _ => None,
        };
        Ok(Seq {
            w: self.w,
            element: Expect::Elem(&slot.elem),
            packed,
            next: 0,
        })
    }
}

impl<'a, 'p> ser::Serializer for Ser<'a, 'p> {
    type Ok = ();
    type Error = Fail;
    type SerializeSeq = Seq<'a, 'p>;
    type SerializeTuple = Seq<'a, 'p>;
    type SerializeTupleStruct = Seq<'a, 'p>;
    type SerializeTupleVariant = Impossible<(), Fail>;
    type SerializeMap = Impossible<(), Fail>;
    type SerializeStruct = Struct<'a, 'p>;
    type SerializeStructVariant = Impossible<(), Fail>;

    #[inline]
    fn serialize_bool(self, v: bool) -> Result<(), Fail> {
        self.primitive(Primitive::Bool, [u8::from(v)])
    }
    #[inline]
    fn serialize_i8(self, v: i8) -> Result<(), Fail> {
        self.primitive(Primitive::Int8, v.to_le_bytes())
    }
    #[inline]
    fn serialize_i16(self, v: i16) -> Result<(), Fail> {
        self.primitive(Primitive::Int16, v.to_le_bytes())
    }
    #[inline]
    fn serialize_i32(self, v: i32) -> Result<(), Fail> {
        self.primitive(Primitive::Int32, v.to_le_bytes())
    }
    #[inline]
    fn serialize_i64(self, v: i64) -> Result<(), Fail> {
        if let Expect::TimeNanos = self.expect {
            let sec = i32::try_from(v.div_euclid(1_000_000_000))
                .map_err(|_| "the time is outside builtin_interfaces/msg/Time's int32 seconds")?;
            self.w.out.put(sec.to_le_bytes());
            let nanosec = v.rem_euclid(1_000_000_000) as u32;
            self.w.out.put(nanosec.to_le_bytes());
            return Ok(());
        }
        self.primitive(Primitive::Int64, v.to_le_bytes())
    }
    #[inline]
    fn serialize_u8(self, v: u8) -> Result<(), Fail> {
        self.primitive(Primitive::UInt8, [v])
    }
    #[inline]
    fn serialize_u16(self, v: u16) -> Result<(), Fail> {
        self.primitive(Primitive::UInt16, v.to_le_bytes())
    }
    #[inline]
    fn serialize_u32(self, v: u32) -> Result<(), Fail> {
        self.primitive(Primitive::UInt32, v.to_le_bytes())
    }
    #[inline]
    fn serialize_u64(self, v: u64) -> Result<(), Fail> {
        if let Expect::DurationSecs = self.expect {
            let sec = i32::try_from(v).map_err(|_| {
                "the duration is longer than builtin_interfaces/msg/Duration's int32 seconds"
            })?;
            self.w.out.put(sec.to_le_bytes());
            return Ok(());
        }
        self.primitive(Primitive::UInt64, v.to_le_bytes())
    }
    #[inline]
    fn serialize_f32(self, v: f32) -> Result<(), Fail> {
        self.primitive(Primitive::Float32, v.to_le_bytes())
    }
    #[inline]
    fn serialize_f64(self, v: f64) -> Result<(), Fail> {
        self.primitive(Primitive::Float64, v.to_le_bytes())
    }
    fn serialize_char(self, _: char) -> Result<(), Fail> {
        Err(self.mismatch("a char"))
    }
    fn serialize_str(self, v: &str) -> Result<(), Fail> {
        match self.expect.unwrap(self.w.plan)? {
            Expect::Elem(&Elem::Str(bound)) => Ok(self.w.out.string(v, bound)?),
            _ => Err(self.mismatch("a string")),
        }
    }
    fn serialize_bytes(self, v: &[u8]) -> Result<(), Fail> {
        match self.expect.unwrap(self.w.plan)? {
            Expect::Field(slot) if slot.arity != Arity::Single && is_bytes(&slot.field.ty.base) => {
                self.w.out.arity(slot.arity, v.len())?;
                self.w.out.buf.extend_from_slice(v);
                Ok(())
            }
            _ => Err(self.mismatch("bytes")),
        }
    }
    fn serialize_none(self) -> Result<(), Fail> {
        Err(self.mismatch("an optional value"))
    }
    fn serialize_some<T: Serialize + ?Sized>(self, _: &T) -> Result<(), Fail> {
        Err(self.mismatch("an optional value"))
    }
    fn serialize_unit(self) -> Result<(), Fail> {
        match self.expect.resolve(self.w.plan) {
            Expect::Message(n) if n.slots.is_empty() => {
                self.w.out.buf.push(0);
                Ok(())
            }
            _ => Err(self.mismatch("no value")),
        }
    }
    fn serialize_unit_struct(self, _: &'static str) -> Result<(), Fail> {
        self.serialize_unit()
    }
    fn serialize_unit_variant(self, _: &'static str, _: u32, v: &'static str) -> Result<(), Fail> {
        Err(self.mismatch(&format!("the enum value `{v}`")))
    }
    #[inline]
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
    fn serialize_seq(self, len: Option<usize>) -> Result<Seq<'a, 'p>, Fail> {
        self.sequence(len)
    }
    fn serialize_tuple(self, len: usize) -> Result<Seq<'a, 'p>, Fail> {
        self.sequence(Some(len))
    }
    fn serialize_tuple_struct(self, _: &'static str, len: usize) -> Result<Seq<'a, 'p>, Fail> {
        self.sequence(Some(len))
    }
    fn serialize_tuple_variant(
        self,
        _: &'static str,
        _: u32,
        v: &'static str,
        _: usize,
    ) -> Result<Self::SerializeTupleVariant, Fail> {
        Err(self.mismatch(&format!("the enum value `{v}`")))
    }
    fn serialize_map(self, _: Option<usize>) -> Result<Self::SerializeMap, Fail> {
        Err(self.mismatch("a map"))
    }
    #[inline(always)]
    fn serialize_struct(self, name: &'static str, len: usize) -> Result<Struct<'a, 'p>, Fail> {
        let Expect::Message(node) = self.expect.resolve(self.w.plan) else {
            return Err(self.not_struct(name));
        };
        let kind = match node.builtin {
            Builtin::Time if name == "Timestamp" && len == 1 => Kind::Time,
            _ if len == node.slots.len() => Kind::Plain,
            _ => return Err(fields(name, len, node)),
        };
        if node.slots.is_empty() {
            // rosidl's placeholder member of an empty structure.
            self.w.out.buf.push(0);
        }
        Ok(Struct {
            w: self.w,
            node,
            kind,
            next: 0,
        })
    }
    fn serialize_struct_variant(
        self,
        _: &'static str,
        _: u32,
        v: &'static str,
        _: usize,
    ) -> Result<Self::SerializeStructVariant, Fail> {
        Err(self.mismatch(&format!("the enum value `{v}`")))
    }
}

#[cold]
fn fields(name: &str, len: usize, node: &Node<'_>) -> Fail {
    Fail::new(format!(
        "`{name}` has {len} fields, `{}` has {}",
        node.message.name,
        node.slots.len()
    ))
}

/// The elements of an array or sequence.
pub(super) struct Seq<'a, 'p> {
    w: &'a mut W<'p>,
    element: Expect<'p>,
    /// The primitive of an array of one (aligned already: see `prim.rs`).
    packed: Option<Primitive>,
    next: usize,
}

impl Seq<'_, '_> {
    #[inline(always)]
    fn element<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Fail> {
        let done = match self.packed {
            Some(p) => value.serialize(PackedSer {
                out: &mut self.w.out,
                p,
            }),
            None => value.serialize(Ser::new(self.w, self.element)),
        };
        self.next += 1;
        done.map_err(|e| e.at(self.next - 1))
    }
}

impl ser::SerializeSeq for Seq<'_, '_> {
    type Ok = ();
    type Error = Fail;
    #[inline]
    fn serialize_element<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Fail> {
        self.element(value)
    }
    fn end(self) -> Result<(), Fail> {
        Ok(())
    }
}

impl ser::SerializeTuple for Seq<'_, '_> {
    type Ok = ();
    type Error = Fail;
    #[inline]
    fn serialize_element<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Fail> {
        self.element(value)
    }
    fn end(self) -> Result<(), Fail> {
        Ok(())
    }
}

impl ser::SerializeTupleStruct for Seq<'_, '_> {
    type Ok = ();
    type Error = Fail;
    #[inline]
    fn serialize_field<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Fail> {
        self.element(value)
    }
    fn end(self) -> Result<(), Fail> {
        Ok(())
    }
}

/// How a struct maps onto its message.
#[derive(Clone, Copy, PartialEq)]
pub(super) enum Kind {
    /// Field by field, the same names in the same order.
    Plain,
    /// `Timestamp { nanos }` as `builtin_interfaces/msg/Time`.
    Time,
}

/// The fields of a struct: the message's, in order.
pub(super) struct Struct<'a, 'p> {
    w: &'a mut W<'p>,
    node: &'p Node<'p>,
    kind: Kind,
    next: usize,
}

impl<'p> Struct<'_, 'p> {
    /// What the field `key` is where it is not simply the next field of the message:
    /// ferroc's `Timestamp` and `std::time::Duration` in their builtin messages, or an
    /// error.
    fn special(&mut self, at: usize, key: &'static str) -> Result<(Expect<'p>, &'p str), Fail> {
        let node = self.node;
        match (self.kind, node.builtin, at, key) {
            (Kind::Time, _, _, "nanos") => return Ok((Expect::TimeNanos, "nanos")),
            (Kind::Time, ..) => {
                return Err(Fail::new(format!(
                    "`{}` has no field `{key}`",
                    node.message.name
                )))
            }
            // `std::time::Duration { secs, nanos }` is builtin_interfaces' Duration.
            (_, Builtin::Duration, 0, "secs") => return Ok((Expect::DurationSecs, "sec")),
            (_, Builtin::Duration, 1, "nanos") => return Ok((Expect::Elem(&UINT32), "nanosec")),
            _ => {}
        }
        let slot = (node.slots.get(at)).ok_or("more fields than the message")?;
        Err(Fail::new(format!(
            "the value's field `{key}` where `{}` has `{}`",
            node.message.name, slot.field.name
        )))
    }
}

impl ser::SerializeStruct for Struct<'_, '_> {
    type Ok = ();
    type Error = Fail;

    #[inline(always)]
    fn serialize_field<T: Serialize + ?Sized>(
        &mut self,
        key: &'static str,
        value: &T,
    ) -> Result<(), Fail> {
        let at = self.next;
        self.next += 1;
        let (expect, name) = match self.node.slots.get(at) {
            Some(slot) if self.kind == Kind::Plain && slot.named(key) => {
                (Expect::of(slot), slot.name)
            }
            _ => self.special(at, key)?,
        };
        (value.serialize(Ser::new(self.w, expect))).map_err(|e| e.within(name))
    }

    fn end(self) -> Result<(), Fail> {
        Ok(())
    }
}
