//! A dynamic value of a ROS 2 message type: what CDR encodes and decodes.

/// One value. A message is a [`Value::Struct`] of its fields in definition order (an
/// empty message has no fields; its wire byte is rosidl's placeholder member).
/// `byte`, `char` and `uint8` are [`Value::U8`]; arrays and sequences of them are
/// [`Value::Bytes`] (images and point clouds stay one buffer).
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    Bool(bool),
    I8(i8),
    U8(u8),
    I16(i16),
    U16(u16),
    I32(i32),
    U32(u32),
    I64(i64),
    U64(u64),
    F32(f32),
    F64(f64),
    String(String),
    /// An array or sequence of `byte`, `char` or `uint8`.
    Bytes(Vec<u8>),
    /// An array or sequence of anything else.
    Array(Vec<Value>),
    /// A message: its fields in order.
    Struct(Vec<Value>),
}

impl Value {
    /// What kind of value this is, for error messages.
    pub fn kind(&self) -> &'static str {
        match self {
            Value::Bool(_) => "bool",
            Value::I8(_) => "int8",
            Value::U8(_) => "uint8",
            Value::I16(_) => "int16",
            Value::U16(_) => "uint16",
            Value::I32(_) => "int32",
            Value::U32(_) => "uint32",
            Value::I64(_) => "int64",
            Value::U64(_) => "uint64",
            Value::F32(_) => "float32",
            Value::F64(_) => "float64",
            Value::String(_) => "string",
            Value::Bytes(_) => "byte array",
            Value::Array(_) => "array",
            Value::Struct(_) => "message",
        }
    }
}
