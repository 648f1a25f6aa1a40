//! A dynamic [`Value`] serialized the way a derived Rust type of its message would be
//! ([`TypedMessage`]), and whatever a deserializer offers read back ([`Any`]): the serde
//! codec checked against the dynamic one for every shipped type.
#![allow(dead_code)]

use ferroc_ros2::def::{Arity, BaseType, FieldType, Message};
use ferroc_ros2::{Registry, Value};
use serde::de::{self, Deserializer, SeqAccess, Visitor};
use serde::ser::{SerializeSeq, SerializeStruct, SerializeTuple, Serializer};
use serde::{Deserialize, Serialize};

fn leak(s: &str) -> &'static str {
    Box::leak(s.to_string().into_boxed_str())
}

/// A dynamic value serialized the way a derived Rust type of the message would be.
struct Typed<'a> {
    reg: &'a Registry,
    ty: &'a FieldType,
    value: &'a Value,
}

pub struct TypedMessage<'a> {
    pub reg: &'a Registry,
    pub m: &'a Message,
    pub value: &'a Value,
}

impl Serialize for TypedMessage<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let Value::Struct(values) = self.value else {
            panic!("a message value")
        };
        if self.m.fields.is_empty() {
            return s.serialize_unit_struct("Empty");
        }
        let mut st = s.serialize_struct(leak(&self.m.name.name), values.len())?;
        for (f, v) in self.m.fields.iter().zip(values) {
            let typed = Typed {
                reg: self.reg,
                ty: &f.ty,
                value: v,
            };
            st.serialize_field(leak(&f.name), &typed)?;
        }
        st.end()
    }
}

impl Serialize for Typed<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let element = FieldType {
            base: self.ty.base.clone(),
            arity: Arity::Single,
        };
        match self.value {
            Value::Bool(v) => s.serialize_bool(*v),
            Value::I8(v) => s.serialize_i8(*v),
            Value::U8(v) => s.serialize_u8(*v),
            Value::I16(v) => s.serialize_i16(*v),
            Value::U16(v) => s.serialize_u16(*v),
            Value::I32(v) => s.serialize_i32(*v),
            Value::U32(v) => s.serialize_u32(*v),
            Value::I64(v) => s.serialize_i64(*v),
            Value::U64(v) => s.serialize_u64(*v),
            Value::F32(v) => s.serialize_f32(*v),
            Value::F64(v) => s.serialize_f64(*v),
            Value::String(v) => s.serialize_str(v),
            Value::Bytes(b) => s.serialize_bytes(b),
            Value::Array(items) if matches!(self.ty.arity, Arity::Fixed(_)) => {
                let mut t = s.serialize_tuple(items.len())?;
                for v in items {
                    t.serialize_element(&self.with(&element, v))?;
                }
                t.end()
            }
            Value::Array(items) => {
                let mut seq = s.serialize_seq(Some(items.len()))?;
                for v in items {
                    seq.serialize_element(&self.with(&element, v))?;
                }
                seq.end()
            }
            Value::Struct(_) => {
                let BaseType::Nested(n) = &self.ty.base else {
                    panic!("a struct of a message")
                };
                let m = self.reg.message(n).unwrap();
                TypedMessage {
                    reg: self.reg,
                    m,
                    value: self.value,
                }
                .serialize(s)
            }
        }
    }
}

impl<'a> Typed<'a> {
    fn with(&self, ty: &'a FieldType, value: &'a Value) -> Typed<'a> {
        Typed {
            reg: self.reg,
            ty,
            value,
        }
    }
}

/// Whatever the deserializer offers, in a form the dynamic values compare with.
#[derive(Debug, PartialEq)]
pub enum Any {
    Leaf(Value),
    List(Vec<Any>),
}

impl<'de> Deserialize<'de> for Any {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Any, D::Error> {
        d.deserialize_any(AnyVisitor)
    }
}

struct AnyVisitor;

macro_rules! leaf {
    ($($f:ident $t:ty => $v:ident),*) => {
        $(fn $f<E: de::Error>(self, v: $t) -> Result<Any, E> {
            Ok(Any::Leaf(Value::$v(v)))
        })*
    };
}

impl<'de> Visitor<'de> for AnyVisitor {
    type Value = Any;
    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("anything")
    }
    leaf!(visit_bool bool => Bool, visit_i8 i8 => I8, visit_u8 u8 => U8, visit_i16 i16 => I16,
        visit_u16 u16 => U16, visit_i32 i32 => I32, visit_u32 u32 => U32, visit_i64 i64 => I64,
        visit_u64 u64 => U64, visit_f32 f32 => F32, visit_f64 f64 => F64,
        visit_string String => String);
    fn visit_str<E: de::Error>(self, v: &str) -> Result<Any, E> {
        Ok(Any::Leaf(Value::String(v.to_string())))
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Any, A::Error> {
        let mut items = Vec::new();
        while let Some(item) = seq.next_element()? {
            items.push(item);
        }
        Ok(Any::List(items))
    }
}

pub fn any_of(v: &Value) -> Any {
    match v {
        Value::Bytes(b) => Any::List(b.iter().map(|x| Any::Leaf(Value::U8(*x))).collect()),
        Value::Array(items) | Value::Struct(items) => Any::List(items.iter().map(any_of).collect()),
        v => Any::Leaf(v.clone()),
    }
}
