//! The serde `Serializer` writing a port's value as CDR (see the module documentation).

use super::{builtin, same, Expect, Fail, Look, UINT32};
use crate::def::{Arity, BaseType, Message, Primitive};
use crate::wire::{is_bytes, Out};
use serde::ser::{self, Impossible, Serialize};

/// The sample being written and where in the message it is.
pub(super) struct W<'r> {
    pub reg: Look<'r>,
    pub out: Out,
    /// The field path, for errors.
    pub path: Vec<&'r str>,
}

/// Serializes one value where the definition expects `expect`.
pub(super) struct Ser<'a, 'r> {
    w: &'a mut W<'r>,
    expect: Expect<'r>,
}

impl<'a, 'r> Ser<'a, 'r> {
    pub(super) fn new(w: &'a mut W<'r>, expect: Expect<'r>) -> Self {
        Ser { w, expect }
    }

    fn mismatch(&self, ours: &str) -> Fail {
        Fail(format!(
            "the value has {ours} where the message has {}",
            self.expect.describe()
        ))
    }

    /// A primitive of the port's type `ours`, written by `write` if the message has
    /// the same primitive here.
    #[inline]
    fn primitive(self, ours: Primitive, write: impl FnOnce(&mut Out)) -> Result<(), Fail> {
        if let Expect::Base(BaseType::Primitive(p)) = self.expect {
            if same(ours, *p) {
                write(&mut self.w.out);
                return Ok(());
            }
        }
        match self.expect.unwrap(self.w.reg)? {
            Expect::Base(BaseType::Primitive(p)) if same(ours, *p) => {
                write(&mut self.w.out);
                Ok(())
            }
            _ => Err(self.mismatch(ours.msg_name())),
        }
    }

    /// The sequence or array field a serde sequence of `len` elements is.
    fn sequence(self, len: Option<usize>) -> Result<Seq<'a, 'r>, Fail> {
        let Expect::Field(ty) = self.expect.unwrap(self.w.reg)? else {
            return Err(self.mismatch("an array"));
        };
        let len = len.ok_or("a sequence of unknown length")?;
        self.w.out.arity(ty.arity, len)?;
        Ok(Seq {
            w: self.w,
            base: &ty.base,
        })
    }
}

impl<'a, 'r> ser::Serializer for Ser<'a, 'r> {
    type Ok = ();
    type Error = Fail;
    type SerializeSeq = Seq<'a, 'r>;
    type SerializeTuple = Seq<'a, 'r>;
    type SerializeTupleStruct = Seq<'a, 'r>;
    type SerializeTupleVariant = Impossible<(), Fail>;
    type SerializeMap = Impossible<(), Fail>;
    type SerializeStruct = Struct<'a, 'r>;
    type SerializeStructVariant = Impossible<(), Fail>;

    fn serialize_bool(self, v: bool) -> Result<(), Fail> {
        self.primitive(Primitive::Bool, |o| o.put([u8::from(v)]))
    }
    fn serialize_i8(self, v: i8) -> Result<(), Fail> {
        self.primitive(Primitive::Int8, |o| o.put(v.to_le_bytes()))
    }
    fn serialize_i16(self, v: i16) -> Result<(), Fail> {
        self.primitive(Primitive::Int16, |o| o.put(v.to_le_bytes()))
    }
    fn serialize_i32(self, v: i32) -> Result<(), Fail> {
        self.primitive(Primitive::Int32, |o| o.put(v.to_le_bytes()))
    }
    fn serialize_i64(self, v: i64) -> Result<(), Fail> {
        if let Expect::TimeNanos = self.expect {
            let sec = i32::try_from(v.div_euclid(1_000_000_000))
                .map_err(|_| "the time is outside builtin_interfaces/msg/Time's int32 seconds")?;
            self.w.out.put(sec.to_le_bytes());
            let nanosec = v.rem_euclid(1_000_000_000) as u32;
            self.w.out.put(nanosec.to_le_bytes());
            return Ok(());
        }
        self.primitive(Primitive::Int64, |o| o.put(v.to_le_bytes()))
    }
    fn serialize_u8(self, v: u8) -> Result<(), Fail> {
        self.primitive(Primitive::UInt8, |o| o.put([v]))
    }
    fn serialize_u16(self, v: u16) -> Result<(), Fail> {
        self.primitive(Primitive::UInt16, |o| o.put(v.to_le_bytes()))
    }
    fn serialize_u32(self, v: u32) -> Result<(), Fail> {
        self.primitive(Primitive::UInt32, |o| o.put(v.to_le_bytes()))
    }
    fn serialize_u64(self, v: u64) -> Result<(), Fail> {
        if let Expect::DurationSecs = self.expect {
            let sec = i32::try_from(v).map_err(|_| {
                "the duration is longer than builtin_interfaces/msg/Duration's int32 seconds"
            })?;
            self.w.out.put(sec.to_le_bytes());
            return Ok(());
        }
        self.primitive(Primitive::UInt64, |o| o.put(v.to_le_bytes()))
    }
    fn serialize_f32(self, v: f32) -> Result<(), Fail> {
        self.primitive(Primitive::Float32, |o| o.put(v.to_le_bytes()))
    }
    fn serialize_f64(self, v: f64) -> Result<(), Fail> {
        self.primitive(Primitive::Float64, |o| o.put(v.to_le_bytes()))
    }
    fn serialize_char(self, _: char) -> Result<(), Fail> {
        Err(self.mismatch("a char"))
    }
    fn serialize_str(self, v: &str) -> Result<(), Fail> {
        match self.expect.unwrap(self.w.reg)? {
            Expect::Base(BaseType::String { bound }) => Ok(self.w.out.string(v, *bound)?),
            _ => Err(self.mismatch("a string")),
        }
    }
    fn serialize_bytes(self, v: &[u8]) -> Result<(), Fail> {
        match self.expect.unwrap(self.w.reg)? {
            Expect::Field(ty) if ty.arity != Arity::Single && is_bytes(&ty.base) => {
                self.w.out.arity(ty.arity, v.len())?;
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
        match self.expect.resolve(self.w.reg)? {
            Expect::Message(m) if m.fields.is_empty() => {
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
    fn serialize_seq(self, len: Option<usize>) -> Result<Seq<'a, 'r>, Fail> {
        self.sequence(len)
    }
    fn serialize_tuple(self, len: usize) -> Result<Seq<'a, 'r>, Fail> {
        self.sequence(Some(len))
    }
    fn serialize_tuple_struct(self, _: &'static str, len: usize) -> Result<Seq<'a, 'r>, Fail> {
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
    fn serialize_struct(self, name: &'static str, len: usize) -> Result<Struct<'a, 'r>, Fail> {
        let Expect::Message(m) = self.expect.resolve(self.w.reg)? else {
            return Err(self.mismatch(&format!("a `{name}`")));
        };
        let kind = match (name, len) {
            ("Timestamp", 1) if builtin(m, "Time") => Kind::Time,
            _ if len == m.fields.len() => Kind::Plain,
            _ => {
                return Err(Fail(format!(
                    "`{name}` has {len} fields, `{}` has {}",
                    m.name,
                    m.fields.len()
                )))
            }
        };
        if m.fields.is_empty() {
            // rosidl's placeholder member of an empty structure.
            self.w.out.buf.push(0);
        }
        Ok(Struct {
            w: self.w,
            m,
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

/// The elements of an array or sequence.
pub(super) struct Seq<'a, 'r> {
    w: &'a mut W<'r>,
    base: &'r BaseType,
}

impl Seq<'_, '_> {
    fn element<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Fail> {
        value.serialize(Ser::new(self.w, Expect::Base(self.base)))
    }
}

impl ser::SerializeSeq for Seq<'_, '_> {
    type Ok = ();
    type Error = Fail;
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
pub(super) struct Struct<'a, 'r> {
    w: &'a mut W<'r>,
    m: &'r Message,
    kind: Kind,
    next: usize,
}

impl ser::SerializeStruct for Struct<'_, '_> {
    type Ok = ();
    type Error = Fail;

    fn serialize_field<T: Serialize + ?Sized>(
        &mut self,
        key: &'static str,
        value: &T,
    ) -> Result<(), Fail> {
        let expect = match (self.kind, key) {
            (Kind::Time, "nanos") => Expect::TimeNanos,
            (Kind::Plain, _) => {
                let f = (self.m.fields.get(self.next)).ok_or("more fields than the message")?;
                // `std::time::Duration { secs, nanos }` is builtin_interfaces' Duration.
                let duration = builtin(self.m, "Duration");
                if duration && (self.next, key) == (0, "secs") {
                    self.next += 1;
                    return value.serialize(Ser::new(self.w, Expect::DurationSecs));
                }
                if duration && (self.next, key) == (1, "nanos") {
                    self.next += 1;
                    return value.serialize(Ser::new(self.w, Expect::Base(&UINT32)));
                }
                if f.name != key {
                    return Err(Fail(format!(
                        "the value's field `{key}` where `{}` has `{}`",
                        self.m.name, f.name
                    )));
                }
                self.w.path.push(&f.name);
                value.serialize(Ser::new(self.w, Expect::Field(&f.ty)))?;
                self.w.path.pop();
                self.next += 1;
                return Ok(());
            }
            _ => return Err(Fail(format!("`{}` has no field `{key}`", self.m.name))),
        };
        value.serialize(Ser::new(self.w, expect))
    }

    fn end(self) -> Result<(), Fail> {
        Ok(())
    }
}
