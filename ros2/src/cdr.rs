//! CDR as ROS 2 sends it (XCDR1, little endian): a 4-byte encapsulation header
//! `00 01 00 00`, then the fields in order, each primitive aligned to its size counted
//! from the end of the header; strings and sequences are a `u32` length first (a string's
//! length counts its terminating NUL); fixed arrays have no length.
//!
//! Decoding is safe against hostile input: every length is checked against the bytes
//! that remain before anything is allocated, bounds and bools are enforced, and a
//! truncated or malformed sample is an [`CdrError`], never a panic.
use std::fmt;

use crate::def::{Arity, BaseType, Field, Message, Primitive, TypeName};
use crate::{Registry, Value};

/// The encapsulation header of little-endian plain CDR.
pub const HEADER: [u8; 4] = [0x00, 0x01, 0x00, 0x00];

/// Nested messages deeper than this are refused (no shipped type comes near it).
const MAX_DEPTH: usize = 32;

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

fn error(path: &[String], message: String) -> CdrError {
    CdrError {
        path: path.join(".").replace(".[", "["),
        message,
    }
}

/// Encodes `value` as a CDR sample of the message type `ty`.
pub fn encode(registry: &Registry, ty: &TypeName, value: &Value) -> Result<Vec<u8>, CdrError> {
    let message = registry
        .message(ty)
        .ok_or_else(|| error(&[], format!("unknown message type `{ty}`")))?;
    let mut w = Writer {
        registry,
        buf: HEADER.to_vec(),
        path: Vec::new(),
    };
    w.message(message, value, 0)?;
    Ok(w.buf)
}

/// Decodes a CDR sample of the message type `ty`.
pub fn decode(registry: &Registry, ty: &TypeName, bytes: &[u8]) -> Result<Value, CdrError> {
    let message = registry
        .message(ty)
        .ok_or_else(|| error(&[], format!("unknown message type `{ty}`")))?;
    match bytes {
        [0x00, 0x01, _, _, ..] => {}
        [0x00, 0x00, _, _, ..] => {
            return Err(error(&[], "the sample is big-endian CDR (header 00 00); ROS 2 over rmw_zenoh sends little-endian (00 01)".into()))
        }
        [a, b, _, _, ..] => {
            return Err(error(&[], format!("the sample's encapsulation header is {a:02x} {b:02x}; expected 00 01 (little-endian CDR)")))
        }
        _ => return Err(error(&[], format!("the sample has {} bytes; even its 4-byte header is missing", bytes.len()))),
    }
    let mut r = Reader {
        registry,
        data: bytes,
        pos: 4,
        path: Vec::new(),
    };
    let value = r.message(message, 0)?;
    let left = bytes.len() - r.pos;
    // Writers may pad the sample to a multiple of 4; more is not this type.
    if left > 3 {
        return Err(error(&[], format!("{left} bytes are left over after the message `{ty}`; the sample is of another type or corrupt")));
    }
    Ok(value)
}

/// The fields a message has on the wire.
fn wire_fields(message: &Message) -> &[Field] {
    &message.fields
}

struct Writer<'r> {
    registry: &'r Registry,
    buf: Vec<u8>,
    path: Vec<String>,
}

impl Writer<'_> {
    fn align(&mut self, n: usize) {
        while (self.buf.len() - 4) % n != 0 {
            self.buf.push(0);
        }
    }

    fn message(&mut self, message: &Message, value: &Value, depth: usize) -> Result<(), CdrError> {
        if depth > MAX_DEPTH {
            return Err(error(&self.path, "messages are nested too deeply".into()));
        }
        let Value::Struct(values) = value else {
            return Err(error(
                &self.path,
                format!(
                    "expected a `{}` message, found {}",
                    message.name,
                    value.kind()
                ),
            ));
        };
        let fields = wire_fields(message);
        if fields.is_empty() {
            // rosidl's placeholder member of an empty structure.
            if !values.is_empty() {
                return Err(error(
                    &self.path,
                    format!("`{}` has no fields, found {}", message.name, values.len()),
                ));
            }
            self.buf.push(0);
            return Ok(());
        }
        if values.len() != fields.len() {
            return Err(error(
                &self.path,
                format!(
                    "`{}` has {} fields, the value has {}",
                    message.name,
                    fields.len(),
                    values.len()
                ),
            ));
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
        match field.ty.arity {
            Arity::Single => self.base(base, value, depth),
            arity => {
                let len = match value {
                    Value::Bytes(b) if is_bytes(base) => b.len(),
                    Value::Array(a) if !is_bytes(base) => a.len(),
                    other => {
                        return Err(error(
                            &self.path,
                            format!("expected an array, found {}", other.kind()),
                        ))
                    }
                };
                match arity {
                    Arity::Fixed(n) if len != n as usize => {
                        return Err(error(
                            &self.path,
                            format!("the array has {n} elements, the value has {len}"),
                        ))
                    }
                    Arity::Bounded(n) if len > n as usize => {
                        return Err(error(
                            &self.path,
                            format!("the sequence holds at most {n} elements, the value has {len}"),
                        ))
                    }
                    Arity::Fixed(_) => {}
                    _ => self.length(len)?,
                }
                match value {
                    Value::Bytes(b) => self.buf.extend_from_slice(b),
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
        }
    }

    fn length(&mut self, len: usize) -> Result<(), CdrError> {
        let len = u32::try_from(len)
            .map_err(|_| error(&self.path, "longer than CDR's 2^32-1 elements".into()))?;
        self.align(4);
        self.buf.extend_from_slice(&len.to_le_bytes());
        Ok(())
    }

    fn base(&mut self, base: &BaseType, value: &Value, depth: usize) -> Result<(), CdrError> {
        match base {
            BaseType::Primitive(p) => self.primitive(*p, value),
            BaseType::String { bound } => {
                let Value::String(s) = value else {
                    return Err(error(
                        &self.path,
                        format!("expected a string, found {}", value.kind()),
                    ));
                };
                if s.contains('\0') {
                    return Err(error(
                        &self.path,
                        "a ROS 2 string cannot contain a NUL character".into(),
                    ));
                }
                if let Some(b) = bound {
                    if s.len() > *b as usize {
                        return Err(error(
                            &self.path,
                            format!(
                                "the string holds at most {b} bytes, the value has {}",
                                s.len()
                            ),
                        ));
                    }
                }
                self.length(s.len() + 1)?;
                self.buf.extend_from_slice(s.as_bytes());
                self.buf.push(0);
                Ok(())
            }
            BaseType::WString { .. } => {
                Err(error(&self.path, "wstring fields are not supported".into()))
            }
            BaseType::Nested(name) => {
                let message = self
                    .registry
                    .message(name)
                    .ok_or_else(|| error(&self.path, format!("unknown message type `{name}`")))?;
                self.message(message, value, depth + 1)
            }
        }
    }

    fn primitive(&mut self, p: Primitive, value: &Value) -> Result<(), CdrError> {
        use Primitive::*;
        self.align(p.size());
        let bytes: Vec<u8> = match (p, value) {
            (Bool, Value::Bool(b)) => vec![u8::from(*b)],
            (Byte | Char | UInt8, Value::U8(v)) => vec![*v],
            (Int8, Value::I8(v)) => v.to_le_bytes().to_vec(),
            (Int16, Value::I16(v)) => v.to_le_bytes().to_vec(),
            (UInt16, Value::U16(v)) => v.to_le_bytes().to_vec(),
            (Int32, Value::I32(v)) => v.to_le_bytes().to_vec(),
            (UInt32, Value::U32(v)) => v.to_le_bytes().to_vec(),
            (Int64, Value::I64(v)) => v.to_le_bytes().to_vec(),
            (UInt64, Value::U64(v)) => v.to_le_bytes().to_vec(),
            (Float32, Value::F32(v)) => v.to_le_bytes().to_vec(),
            (Float64, Value::F64(v)) => v.to_le_bytes().to_vec(),
            (p, v) => {
                return Err(error(
                    &self.path,
                    format!("expected {}, found {}", p.msg_name(), v.kind()),
                ))
            }
        };
        self.buf.extend_from_slice(&bytes);
        Ok(())
    }
}

/// Arrays of these are one byte buffer ([`Value::Bytes`]).
fn is_bytes(base: &BaseType) -> bool {
    matches!(
        base,
        BaseType::Primitive(Primitive::Byte | Primitive::Char | Primitive::UInt8)
    )
}

struct Reader<'r, 'd> {
    registry: &'r Registry,
    data: &'d [u8],
    pos: usize,
    path: Vec<String>,
}

impl<'d> Reader<'_, 'd> {
    fn remaining(&self) -> usize {
        self.data.len() - self.pos
    }

    fn take(&mut self, n: usize) -> Result<&'d [u8], CdrError> {
        if n > self.remaining() {
            return Err(error(
                &self.path,
                format!(
                    "the sample ends early: {n} more bytes needed at offset {}, {} left",
                    self.pos,
                    self.remaining()
                ),
            ));
        }
        let data: &'d [u8] = self.data;
        let s = &data[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    fn align(&mut self, n: usize) -> Result<(), CdrError> {
        let pad = (n - (self.pos - 4) % n) % n;
        self.take(pad).map(|_| ())
    }

    fn array<const N: usize>(&mut self) -> Result<[u8; N], CdrError> {
        self.align(N)?;
        Ok(self.take(N)?.try_into().expect("N bytes"))
    }

    fn length(&mut self, min_element: usize) -> Result<usize, CdrError> {
        let len = u32::from_le_bytes(self.array::<4>()?) as usize;
        // Each element takes at least `min_element` bytes: a length the rest of the
        // sample cannot hold is refused before anything is allocated.
        if len.saturating_mul(min_element) > self.remaining() {
            return Err(error(
                &self.path,
                format!(
                    "a length of {len} elements does not fit in the {} bytes left of the sample",
                    self.remaining()
                ),
            ));
        }
        Ok(len)
    }

    fn message(&mut self, message: &Message, depth: usize) -> Result<Value, CdrError> {
        if depth > MAX_DEPTH {
            return Err(error(&self.path, "messages are nested too deeply".into()));
        }
        let fields = wire_fields(message);
        if fields.is_empty() {
            self.take(1)?;
            return Ok(Value::Struct(Vec::new()));
        }
        let mut values = Vec::with_capacity(fields.len());
        for field in fields {
            self.path.push(field.name.clone());
            values.push(self.field(field, depth)?);
            self.path.pop();
        }
        Ok(Value::Struct(values))
    }

    fn field(&mut self, field: &Field, depth: usize) -> Result<Value, CdrError> {
        let base = &field.ty.base;
        let len = match field.ty.arity {
            Arity::Single => return self.base(base, depth),
            Arity::Fixed(n) => n as usize,
            Arity::Bounded(n) => {
                let len = self.length(min_size(base))?;
                if len > n as usize {
                    return Err(error(
                        &self.path,
                        format!("the sequence holds at most {n} elements, the sample has {len}"),
                    ));
                }
                len
            }
            Arity::Unbounded => self.length(min_size(base))?,
        };
        if is_bytes(base) {
            return Ok(Value::Bytes(self.take(len)?.to_vec()));
        }
        if len.saturating_mul(min_size(base)) > self.remaining() {
            return Err(error(
                &self.path,
                format!(
                    "the array of {len} elements does not fit in the {} bytes left of the sample",
                    self.remaining()
                ),
            ));
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
            BaseType::Primitive(p) => self.primitive(*p),
            BaseType::String { bound } => {
                let len = self.length(1)?;
                if len == 0 {
                    return Err(error(&self.path, "a string's length counts its terminating NUL, so it is at least 1; found 0".into()));
                }
                let bytes = self.take(len)?;
                let (text, nul) = bytes.split_at(len - 1);
                if nul != [0] {
                    return Err(error(
                        &self.path,
                        "the string does not end with a NUL byte".into(),
                    ));
                }
                let text = std::str::from_utf8(text)
                    .map_err(|_| error(&self.path, "the string is not UTF-8".into()))?
                    .to_string();
                if let Some(b) = bound {
                    if text.len() > *b as usize {
                        return Err(error(
                            &self.path,
                            format!(
                                "the string holds at most {b} bytes, the sample has {}",
                                text.len()
                            ),
                        ));
                    }
                }
                Ok(Value::String(text))
            }
            BaseType::WString { .. } => {
                Err(error(&self.path, "wstring fields are not supported".into()))
            }
            BaseType::Nested(name) => {
                let message = self
                    .registry
                    .message(name)
                    .ok_or_else(|| error(&self.path, format!("unknown message type `{name}`")))?;
                self.message(message, depth + 1)
            }
        }
    }

    fn primitive(&mut self, p: Primitive) -> Result<Value, CdrError> {
        use Primitive::*;
        Ok(match p {
            Bool => match self.array::<1>()?[0] {
                0 => Value::Bool(false),
                1 => Value::Bool(true),
                b => {
                    return Err(error(
                        &self.path,
                        format!("a bool is 0 or 1, the sample has {b}"),
                    ))
                }
            },
            Byte | Char | UInt8 => Value::U8(self.array::<1>()?[0]),
            Int8 => Value::I8(i8::from_le_bytes(self.array()?)),
            Int16 => Value::I16(i16::from_le_bytes(self.array()?)),
            UInt16 => Value::U16(u16::from_le_bytes(self.array()?)),
            Int32 => Value::I32(i32::from_le_bytes(self.array()?)),
            UInt32 => Value::U32(u32::from_le_bytes(self.array()?)),
            Int64 => Value::I64(i64::from_le_bytes(self.array()?)),
            UInt64 => Value::U64(u64::from_le_bytes(self.array()?)),
            Float32 => Value::F32(f32::from_le_bytes(self.array()?)),
            Float64 => Value::F64(f64::from_le_bytes(self.array()?)),
        })
    }
}

/// The fewest bytes one element of this type takes on the wire (padding aside).
fn min_size(base: &BaseType) -> usize {
    match base {
        BaseType::Primitive(p) => p.size(),
        BaseType::String { .. } | BaseType::WString { .. } => 5,
        BaseType::Nested(_) => 1,
    }
}
