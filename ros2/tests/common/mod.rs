//! Values of any registered type for the tests: deterministic from a seed, covering
//! every kind of field (empty, full and in-between arrays, strings at their bounds).
#![allow(dead_code)]

pub mod typed;

use ferroc_ros2::def::{Arity, BaseType, Message, Primitive, TypeName};
use ferroc_ros2::{Registry, Value};

/// A small deterministic generator (xorshift64*).
pub struct Gen(u64);

impl Gen {
    pub fn new(seed: u64) -> Self {
        Gen(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }

    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    fn below(&mut self, n: u64) -> u64 {
        if n == 0 {
            0
        } else {
            self.next() % n
        }
    }
}

/// A value of the message `ty`.
pub fn value_of(registry: &Registry, ty: &TypeName, g: &mut Gen) -> Value {
    let message = registry.message(ty).expect("known type");
    message_value(registry, message, g)
}

fn message_value(registry: &Registry, message: &Message, g: &mut Gen) -> Value {
    Value::Struct(
        message
            .fields
            .iter()
            .map(|f| {
                let len = match f.ty.arity {
                    Arity::Single => return base_value(registry, &f.ty.base, g),
                    Arity::Fixed(n) => n as u64,
                    Arity::Bounded(n) => g.below(u64::from(n) + 1),
                    Arity::Unbounded => g.below(5),
                };
                if matches!(
                    f.ty.base,
                    BaseType::Primitive(Primitive::Byte | Primitive::Char | Primitive::UInt8)
                ) {
                    Value::Bytes((0..len).map(|_| g.next() as u8).collect())
                } else {
                    Value::Array(
                        (0..len)
                            .map(|_| base_value(registry, &f.ty.base, g))
                            .collect(),
                    )
                }
            })
            .collect(),
    )
}

fn base_value(registry: &Registry, base: &BaseType, g: &mut Gen) -> Value {
    match base {
        BaseType::Primitive(p) => primitive_value(*p, g),
        BaseType::String { bound } => {
            let max = bound.map_or(12, u64::from);
            let len = g.below(max + 1);
            Value::String(
                (0..len)
                    .map(|_| (b'a' + (g.below(26) as u8)) as char)
                    .collect(),
            )
        }
        BaseType::WString { .. } => panic!("no shipped type has a wstring"),
        BaseType::Nested(name) => value_of(registry, name, g),
    }
}

fn primitive_value(p: Primitive, g: &mut Gen) -> Value {
    use Primitive::*;
    let r = g.next();
    match p {
        Bool => Value::Bool(r & 1 == 1),
        Byte | Char | UInt8 => Value::U8(r as u8),
        Int8 => Value::I8(r as i8),
        Int16 => Value::I16(r as i16),
        UInt16 => Value::U16(r as u16),
        Int32 => Value::I32(r as i32),
        UInt32 => Value::U32(r as u32),
        Int64 => Value::I64(r as i64),
        UInt64 => Value::U64(r),
        Float32 => Value::F32((r as i32) as f32 / 1024.0),
        Float64 => Value::F64((r as i64) as f64 / 3.0e9),
    }
}
