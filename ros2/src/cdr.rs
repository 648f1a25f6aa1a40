//! CDR as ROS 2 sends it (XCDR1, little endian): a 4-byte encapsulation header
//! `00 01 00 00`, then the fields in order, each primitive aligned to its size counted
//! from the end of the header; strings and sequences are a `u32` length first (a string's
//! length counts its terminating NUL); fixed arrays have no length.
//!
//! This is the codec of a dynamic [`Value`] (the interop tests and tools); a port's own
//! value is encoded by [`serde_cdr`](crate::serde_cdr). Both follow the rules of
//! `wire.rs`, written once.
//!
//! Decoding is safe against hostile input: every length is checked against the bytes
//! that remain before anything is allocated, bounds and bools are enforced, and a
//! truncated or malformed sample is an [`CdrError`], never a panic.
use std::fmt;

use crate::def::{Arity, BaseType, Field, Message, Primitive, TypeName};
use crate::wire::{is_bytes, In, Out, MAX_DEPTH};
use crate::{Registry, Value};

pub use crate::wire::HEADER;

/// Why a value could not be encoded or a sample decoded.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CdrError {
    /// The field path (`ranges[3]`, `pose.pose.position.x`); empty for the whole sample.
    pub path: String,
    pub message: String,
}

impl fmt::Display for CdrError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.path.is_empty() {
            write!(f, "{}", self.message)
        } else {
            write!(f, "at `{}`: {}", self.path, self.message)
        }
    }
}

impl std::error::Error for CdrError {}

pub(crate) fn error<S: AsRef<str>>(path: &[S], message: String) -> CdrError {
    let path: Vec<&str> = path.iter().map(AsRef::as_ref).collect();
    CdrError {
        path: path.join(".").replace(".[", "["),
        message,
    }
}

/// Encodes `value` as a CDR sample of the message type `ty`.
pub fn encode(registry: &Registry, ty: &TypeName, value: &Value) -> Result<Vec<u8>, CdrError> {
    let message = registry
        .message(ty)
        .ok_or_else(|| error::<&str>(&[], format!("unknown message type `{ty}`")))?;
    let mut w = Writer {
        registry,
        out: Out::new(Vec::new()),
        path: Vec::new(),
    };
    w.message(message, value, 0)?;
    Ok(w.out.buf)
}

/// Decodes a CDR sample of the message type `ty`.
pub fn decode(registry: &Registry, ty: &TypeName, bytes: &[u8]) -> Result<Value, CdrError> {
    let message = registry
        .message(ty)
        .ok_or_else(|| error::<&str>(&[], format!("unknown message type `{ty}`")))?;
    let input = In::new(bytes).map_err(|e| error::<&str>(&[], e))?;
    let mut r = Reader {
        registry,
        input,
        path: Vec::new(),
    };
    let value = r.message(message, 0)?;
    r.input.finish(ty).map_err(|e| error::<&str>(&[], e))?;
    Ok(value)
}

struct Writer<'r> {
    registry: &'r Registry,
    out: Out,
    path: Vec<String>,
}

impl Writer<'_> {
    fn fail(&self, message: String) -> CdrError {
        error(&self.path, message)
    }

    fn message(&mut self, message: &Message, value: &Value, depth: usize) -> Result<(), CdrError> {
        if depth > MAX_DEPTH {
            return Err(self.fail("messages are nested too deeply".into()));
        }
        let Value::Struct(values) = value else {
            return Err(self.fail(format!(
                "expected a `{}` message, found {}",
                message.name,
                value.kind()
            )));
        };
        let fields = &message.fields;
        if fields.is_empty() {
            // rosidl's placeholder member of an empty structure.
            if !values.is_empty() {
                return Err(self.fail(format!(
                    "`{}` has no fields, found {}",
                    message.name,
                    values.len()
                )));
            }
            self.out.buf.push(0);
            return Ok(());
        }
        if values.len() != fields.len() {
            return Err(self.fail(format!(
                "`{}` has {} fields, the value has {}",
                message.name,
                fields.len(),
                values.len()
            )));
        }
        for (field, v) in fields.iter().zip(values) {
            self.path.push(field.name.clone());
            self.field(field, v, depth)?;
            self.path.pop();
        }
        Ok(())
    }

    fn field(&mut self, field: &Field, value: &Value, depth: usize) -> Result<(), CdrError> {
        let base = &field.ty.base;
        if field.ty.arity == Arity::Single {
            return self.base(base, value, depth);
        }
        let len = match value {
            Value::Bytes(b) if is_bytes(base) => b.len(),
            Value::Array(a) if !is_bytes(base) => a.len(),
            other => return Err(self.fail(format!("expected an array, found {}", other.kind()))),
        };
        self.out
            .arity(field.ty.arity, len)
            .map_err(|e| self.fail(e))?;
        match value {
            Value::Bytes(b) => self.out.buf.extend_from_slice(b),
            Value::Array(items) => {
                for (i, item) in items.iter().enumerate() {
                    self.path.push(format!("[{i}]"));
                    self.base(base, item, depth)?;
                    self.path.pop();
                }
            }
            _ => unreachable!("checked above"),
        }
        Ok(())
    }

    fn base(&mut self, base: &BaseType, value: &Value, depth: usize) -> Result<(), CdrError> {
        match base {
            BaseType::Primitive(p) => self.primitive(*p, value),
            BaseType::String { bound } => {
                let Value::String(s) = value else {
                    return Err(self.fail(format!("expected a string, found {}", value.kind())));
                };
                self.out.string(s, *bound).map_err(|e| self.fail(e))
            }
            BaseType::WString { .. } => Err(self.fail("wstring fields are not supported".into())),
            BaseType::Nested(name) => {
                let message = self
                    .registry
                    .message(name)
                    .ok_or_else(|| self.fail(format!("unknown message type `{name}`")))?;
                self.message(message, value, depth + 1)
            }
        }
    }

    fn primitive(&mut self, p: Primitive, value: &Value) -> Result<(), CdrError> {
        use Primitive::*;
        let out = &mut self.out;
        match (p, value) {
            (Bool, Value::Bool(b)) => out.put([u8::from(*b)]),
            (Byte | Char | UInt8, Value::U8(v)) => out.put([*v]),
            (Int8, Value::I8(v)) => out.put(v.to_le_bytes()),
            (Int16, Value::I16(v)) => out.put(v.to_le_bytes()),
            (UInt16, Value::U16(v)) => out.put(v.to_le_bytes()),
            (Int32, Value::I32(v)) => out.put(v.to_le_bytes()),
            (UInt32, Value::U32(v)) => out.put(v.to_le_bytes()),
            (Int64, Value::I64(v)) => out.put(v.to_le_bytes()),
            (UInt64, Value::U64(v)) => out.put(v.to_le_bytes()),
            (Float32, Value::F32(v)) => out.put(v.to_le_bytes()),
            (Float64, Value::F64(v)) => out.put(v.to_le_bytes()),
            (p, v) => {
                return Err(self.fail(format!("expected {}, found {}", p.msg_name(), v.kind())))
            }
        }
        Ok(())
    }
}

/// Reads dynamic values; also what the serde codec skips the fields around a port's
/// one field with.
pub(crate) struct Reader<'r, 'd> {
    pub registry: &'r Registry,
    pub input: In<'d>,
    pub path: Vec<String>,
}

impl Reader<'_, '_> {
    fn fail(&self, message: String) -> CdrError {
        error(&self.path, message)
    }

    pub fn message(&mut self, message: &Message, depth: usize) -> Result<Value, CdrError> {
        if depth > MAX_DEPTH {
            return Err(self.fail("messages are nested too deeply".into()));
        }
        if message.fields.is_empty() {
            self.input.take(1).map_err(|e| self.fail(e))?;
            return Ok(Value::Struct(Vec::new()));
        }
        let mut values = Vec::with_capacity(message.fields.len());
        for field in &message.fields {
            self.path.push(field.name.clone());
            values.push(self.field(field, depth)?);
            self.path.pop();
        }
        Ok(Value::Struct(values))
    }

    pub fn field(&mut self, field: &Field, depth: usize) -> Result<Value, CdrError> {
        let base = &field.ty.base;
        if field.ty.arity == Arity::Single {
            return self.base(base, depth);
        }
        let len = (self.input.elements(field.ty.arity, base)).map_err(|e| self.fail(e))?;
        if is_bytes(base) {
            let bytes = self.input.take(len).map_err(|e| self.fail(e))?;
            return Ok(Value::Bytes(bytes.to_vec()));
        }
        let mut items = Vec::with_capacity(len);
        for i in 0..len {
            self.path.push(format!("[{i}]"));
            items.push(self.base(base, depth)?);
            self.path.pop();
        }
        Ok(Value::Array(items))
    }

    fn base(&mut self, base: &BaseType, depth: usize) -> Result<Value, CdrError> {
        match base {
            BaseType::Primitive(p) => self.primitive(*p).map_err(|e| self.fail(e)),
            BaseType::String { bound } => match self.input.string(*bound) {
                Ok(text) => Ok(Value::String(text.to_string())),
                Err(e) => Err(self.fail(e)),
            },
            BaseType::WString { .. } => Err(self.fail("wstring fields are not supported".into())),
            BaseType::Nested(name) => {
                let message = self
                    .registry
                    .message(name)
                    .ok_or_else(|| self.fail(format!("unknown message type `{name}`")))?;
                self.message(message, depth + 1)
            }
        }
    }

    fn primitive(&mut self, p: Primitive) -> Result<Value, String> {
        use Primitive::*;
        let r = &mut self.input;
        Ok(match p {
            Bool => Value::Bool(r.bool()?),
            Byte | Char | UInt8 => Value::U8(r.get::<1>()?[0]),
            Int8 => Value::I8(i8::from_le_bytes(r.get()?)),
            Int16 => Value::I16(i16::from_le_bytes(r.get()?)),
            UInt16 => Value::U16(u16::from_le_bytes(r.get()?)),
            Int32 => Value::I32(i32::from_le_bytes(r.get()?)),
            UInt32 => Value::U32(u32::from_le_bytes(r.get()?)),
            Int64 => Value::I64(i64::from_le_bytes(r.get()?)),
            UInt64 => Value::U64(u64::from_le_bytes(r.get()?)),
            Float32 => Value::F32(f32::from_le_bytes(r.get()?)),
            Float64 => Value::F64(f64::from_le_bytes(r.get()?)),
        })
    }
}
