//! CDR's rules in one place (XCDR1, little endian): alignment counted from the end of
//! the 4-byte encapsulation header, `u32` lengths, strings with their NUL, the fewest
//! bytes an element can take. Both codecs write and read through these: the dynamic
//! [`Value`](crate::Value) codec ([`cdr`](crate::cdr)) and the serde codec of a port's
//! own value ([`serde_cdr`](crate::serde_cdr)).
//!
//! Errors are plain messages; the codecs add the field path.

use crate::def::{Arity, BaseType, FieldType, Message, Primitive};
use crate::Registry;

/// The encapsulation header of little-endian plain CDR.
pub const HEADER: [u8; 4] = [0x00, 0x01, 0x00, 0x00];

/// Nested messages deeper than this are refused (no shipped type comes near it).
pub(crate) const MAX_DEPTH: usize = 32;

/// A sample being written: the header first, then the fields.
pub(crate) struct Out {
    pub buf: Vec<u8>,
}

impl Out {
    /// A sample written into `buf` (cleared, its capacity kept).
    pub fn new(mut buf: Vec<u8>) -> Out {
        buf.clear();
        buf.extend_from_slice(&HEADER);
        Out { buf }
    }

    /// Pads to a multiple of `n` (1, 2, 4 or 8) counted from the end of the header.
    #[inline]
    pub fn align(&mut self, n: usize) {
        let pad = (self.buf.len() - HEADER.len()).wrapping_neg() & (n - 1);
        if pad > 0 {
            self.buf.resize(self.buf.len() + pad, 0);
        }
    }

    /// A primitive of `N` bytes, aligned to `N`.
    #[inline]
    pub fn put<const N: usize>(&mut self, bytes: [u8; N]) {
        self.align(N);
        self.buf.extend_from_slice(&bytes);
    }

    /// A sequence's or string's length.
    pub fn length(&mut self, len: usize) -> Result<(), String> {
        let len = u32::try_from(len).map_err(|_| "longer than CDR's 2^32-1 elements")?;
        self.put(len.to_le_bytes());
        Ok(())
    }

    /// The length of a sequence of `arity` holding `len` elements (nothing for a fixed
    /// array, whose length must be its own).
    pub fn arity(&mut self, arity: Arity, len: usize) -> Result<(), String> {
        match arity {
            Arity::Fixed(n) if len != n as usize => {
                Err(format!("the array has {n} elements, the value has {len}"))
            }
            Arity::Bounded(n) if len > n as usize => Err(format!(
                "the sequence holds at most {n} elements, the value has {len}"
            )),
            Arity::Fixed(_) | Arity::Single => Ok(()),
            Arity::Bounded(_) | Arity::Unbounded => self.length(len),
        }
    }

    /// A string: its length counting the NUL, its bytes, the NUL.
    pub fn string(&mut self, s: &str, bound: Option<u32>) -> Result<(), String> {
        if s.as_bytes().contains(&0) {
            return Err("a ROS 2 string cannot contain a NUL character".into());
        }
        if let Some(b) = bound.filter(|b| s.len() > *b as usize) {
            return Err(format!(
                "the string holds at most {b} bytes, the value has {}",
                s.len()
            ));
        }
        self.length(s.len() + 1)?;
        self.buf.extend_from_slice(s.as_bytes());
        self.buf.push(0);
        Ok(())
    }

    /// The zero value of a field: numbers 0, strings empty, sequences empty, fixed
    /// arrays of zeros.
    pub fn zero_field(
        &mut self,
        reg: &Registry,
        ty: &FieldType,
        depth: usize,
    ) -> Result<(), String> {
        match ty.arity {
            Arity::Single => self.zero_base(reg, &ty.base, depth),
            Arity::Fixed(n) => (0..n).try_for_each(|_| self.zero_base(reg, &ty.base, depth)),
            Arity::Bounded(_) | Arity::Unbounded => self.length(0),
        }
    }

    fn zero_base(&mut self, reg: &Registry, base: &BaseType, depth: usize) -> Result<(), String> {
        match base {
            BaseType::Primitive(p) => {
                self.align(p.size());
                self.buf.resize(self.buf.len() + p.size(), 0);
                Ok(())
            }
            BaseType::String { .. } => self.string("", None),
            BaseType::WString { .. } => Err("wstring fields are not supported".into()),
            BaseType::Nested(n) => self.zero_message(reg, message(reg, n)?, depth + 1),
        }
    }

    pub fn zero_message(
        &mut self,
        reg: &Registry,
        m: &Message,
        depth: usize,
    ) -> Result<(), String> {
        if depth > MAX_DEPTH {
            return Err("messages are nested too deeply".into());
        }
        if m.fields.is_empty() {
            self.buf.push(0);
        }
        m.fields
            .iter()
            .try_for_each(|f| self.zero_field(reg, &f.ty, depth))
    }
}

/// The message type `name`, or why not.
pub(crate) fn message<'r>(
    reg: &'r Registry,
    name: &crate::def::TypeName,
) -> Result<&'r Message, String> {
    reg.message(name)
        .ok_or_else(|| format!("unknown message type `{name}`"))
}

/// A sample being read, bounded against hostile input: nothing is read or allocated
/// past its end.
#[derive(Clone)]
pub(crate) struct In<'d> {
    data: &'d [u8],
    pub pos: usize,
}

impl<'d> In<'d> {
    /// A sample whose header says little-endian plain CDR, read after the header.
    pub fn new(data: &'d [u8]) -> Result<In<'d>, String> {
        match data {
            [0x00, 0x01, _, _, ..] => Ok(In { data, pos: 4 }),
            [0x00, 0x00, _, _, ..] => Err("the sample is big-endian CDR (header 00 00); ROS 2 over rmw_zenoh sends little-endian (00 01)".into()),
            [a, b, _, _, ..] => Err(format!("the sample's encapsulation header is {a:02x} {b:02x}; expected 00 01 (little-endian CDR)")),
            _ => Err(format!("the sample has {} bytes; even its 4-byte header is missing", data.len())),
        }
    }

    /// The sample is read whole (writers may pad it to a multiple of 4; more is not
    /// this type).
    pub fn finish(&self, ty: &impl std::fmt::Display) -> Result<(), String> {
        let left = self.remaining();
        if left > 3 {
            return Err(format!("{left} bytes are left over after the message `{ty}`; the sample is of another type or corrupt"));
        }
        Ok(())
    }

    pub fn remaining(&self) -> usize {
        self.data.len() - self.pos
    }

    #[inline]
    pub fn take(&mut self, n: usize) -> Result<&'d [u8], String> {
        if n > self.remaining() {
            return Err(self.short(n));
        }
        let data: &'d [u8] = self.data;
        let s = &data[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    #[cold]
    fn short(&self, n: usize) -> String {
        format!(
            "the sample ends early: {n} more bytes needed at offset {}, {} left",
            self.pos,
            self.remaining()
        )
    }

    /// Skips to a multiple of `n` (1, 2, 4 or 8) counted from the end of the header.
    #[inline]
    pub fn align(&mut self, n: usize) -> Result<(), String> {
        let pad = (self.pos - HEADER.len()).wrapping_neg() & (n - 1);
        if pad > 0 {
            self.take(pad)?;
        }
        Ok(())
    }

    /// `n` bytes (1, 2, 4 or 8: one primitive) aligned to `n`, with one bounds check.
    #[inline]
    pub fn aligned(&mut self, n: usize) -> Result<&'d [u8], String> {
        let start = self.pos + ((self.pos - HEADER.len()).wrapping_neg() & (n - 1));
        let data: &'d [u8] = self.data;
        match data.get(start..start.saturating_add(n)) {
            Some(bytes) => {
                self.pos = start + n;
                Ok(bytes)
            }
            None => Err(self.short(start - self.pos + n)),
        }
    }

    /// A primitive of `N` bytes, aligned to `N`.
    #[inline]
    pub fn get<const N: usize>(&mut self) -> Result<[u8; N], String> {
        let start = self.pos + ((self.pos - HEADER.len()).wrapping_neg() & (N - 1));
        let data: &'d [u8] = self.data;
        match data.get(start..).and_then(<[u8]>::first_chunk::<N>) {
            Some(bytes) => {
                self.pos = start + N;
                Ok(*bytes)
            }
            None => Err(self.short(start - self.pos + N)),
        }
    }

    pub fn bool(&mut self) -> Result<bool, String> {
        match self.get::<1>()?[0] {
            0 => Ok(false),
            1 => Ok(true),
            b => Err(format!("a bool is 0 or 1, the sample has {b}")),
        }
    }

    /// A length of elements of at least `min_element` bytes each: one the rest of the
    /// sample cannot hold is refused before anything is allocated.
    pub fn length(&mut self, min_element: usize) -> Result<usize, String> {
        let len = u32::from_le_bytes(self.get::<4>()?) as usize;
        if len.saturating_mul(min_element) > self.remaining() {
            return Err(format!(
                "a length of {len} elements does not fit in the {} bytes left of the sample",
                self.remaining()
            ));
        }
        Ok(len)
    }

    /// The number of elements of a field of `arity` over `base` (read for sequences,
    /// the array's own for fixed arrays), checked against the bytes left.
    pub fn elements(&mut self, arity: Arity, base: &BaseType) -> Result<usize, String> {
        let min = min_size(base);
        let len = match arity {
            Arity::Single => 1,
            Arity::Fixed(n) => n as usize,
            Arity::Bounded(n) => {
                let len = self.length(min)?;
                if len > n as usize {
                    return Err(format!(
                        "the sequence holds at most {n} elements, the sample has {len}"
                    ));
                }
                len
            }
            Arity::Unbounded => self.length(min)?,
        };
        if len.saturating_mul(min) > self.remaining() {
            return Err(format!(
                "the array of {len} elements does not fit in the {} bytes left of the sample",
                self.remaining()
            ));
        }
        Ok(len)
    }

    /// A string of at most `bound` bytes.
    pub fn string(&mut self, bound: Option<u32>) -> Result<&'d str, String> {
        let len = self.length(1)?;
        if len == 0 {
            return Err(
                "a string's length counts its terminating NUL, so it is at least 1; found 0".into(),
            );
        }
        let bytes = self.take(len)?;
        let (text, nul) = bytes.split_at(len - 1);
        if nul != [0] {
            return Err("the string does not end with a NUL byte".into());
        }
        let text = std::str::from_utf8(text).map_err(|_| "the string is not UTF-8")?;
        if let Some(b) = bound.filter(|b| text.len() > *b as usize) {
            return Err(format!(
                "the string holds at most {b} bytes, the sample has {}",
                text.len()
            ));
        }
        Ok(text)
    }
}

/// Arrays of these are one byte buffer.
pub(crate) fn is_bytes(base: &BaseType) -> bool {
    matches!(
        base,
        BaseType::Primitive(Primitive::Byte | Primitive::Char | Primitive::UInt8)
    )
}

/// The fewest bytes one element of this type takes on the wire (padding aside).
pub(crate) fn min_size(base: &BaseType) -> usize {
    match base {
        BaseType::Primitive(p) => p.size(),
        BaseType::String { .. } | BaseType::WString { .. } => 5,
        BaseType::Nested(_) => 1,
    }
}
