//! Values that cross between parts: how a registered value type is encoded.
//!
//! A connection between two parts (two processes, maybe two computers) carries the
//! reader's value type as bytes. The model marks such types `serde="true"`; their
//! crates derive `Serialize`/`Deserialize` and register them with
//! `Registry::register_serde` (`ferroc_app::builder`). The encoding
//! is postcard: compact, and exact for floats (an infinite laser range stays infinite).
//!
//! A port published or subscribed as a ROS 2 topic carries its value as the message's
//! CDR instead ([`Codec::ros2_encode`], [`Codec::ros2_decode`]): written straight from
//! the value by `ferroc_ros2::serde_cdr`, guided by the message definition, exact for
//! floats too.
//!
//! Like the rest of the value table these are plain function pointers, monomorphised
//! when the type is registered, working on the type-erased [`DynIn`]/[`DynOut`].

use super::bytes::{self, Holder};
use super::lend::{Chain, Kept, LentBuffer, OnePass, Piece, Split};
use super::value::PortValue;
use super::value_table::{DynIn, DynOut};
use ferroc_ros2::serde_cdr::{self, Shape};
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::borrow::Borrow;
use std::cell::Cell;
use std::sync::Arc;

/// [`Codec::encode_with`] for one type.
type EncodeWith = fn(&DynIn, &mut dyn FnMut(&Encoder<'_>)) -> Result<(), String>;

/// [`Codec::decode_parts`] for one type.
type DecodeParts = fn(&DynOut, &[Arc<dyn Holder>]) -> Result<(), String>;

/// Encoding and decoding of one value type (an entry of the value table).
#[derive(Clone, Copy)]
pub struct Codec {
    encode: fn(&DynIn, &mut Vec<u8>) -> Result<(), String>,
    encode_with: EncodeWith,
    decode: fn(&DynOut, &[u8]) -> Result<(), String>,
    decode_parts: DecodeParts,
    json: fn(&DynIn, &mut Vec<u8>) -> Result<(), String>,
    from_json: fn(Option<&DynOut>, &[u8]) -> Result<(), String>,
    ros2_encode: fn(&DynIn, &Shape<'_>, &str, &mut Vec<u8>) -> Result<(), String>,
    ros2_decode: fn(&DynOut, &Shape<'_>, &[u8]) -> Result<(), String>,
}

impl Codec {
    /// The functions for `T`.
    pub(crate) fn of<T: PortValue + Serialize + DeserializeOwned>() -> Self {
        Codec {
            encode: encode::<T>,
            encode_with: encode_with::<T>,
            decode: decode::<T>,
            decode_parts: decode_parts::<T>,
            json: json::<T>,
            from_json: from_json::<T>,
            ros2_encode: ros2_encode::<T>,
            ros2_decode: ros2_decode::<T>,
        }
    }

    /// The functions for `T`, a type its library maps to a ROS 2 message of its own
    /// ([`Ros2Message`](crate::Ros2Message)): its ROS 2 ends write and read the message
    /// through the type's functions instead of its serde form.
    pub(crate) fn of_ros2<T: crate::Ros2Message>() -> Self {
        Codec {
            ros2_encode: crate::ros2_message::encode::<T>,
            ros2_decode: crate::ros2_message::decode::<T>,
            ..Self::of::<T>()
        }
    }

    /// Replaces `bytes` with the latest value of `from` (made by the same table entry).
    pub fn encode(&self, from: &DynIn, bytes: &mut Vec<u8>) -> Result<(), String> {
        (self.encode)(from, bytes)
    }

    /// Hands `then` the latest value of `from`, ready to be encoded into a buffer of
    /// its exact encoded size ([`Encoder`]): the caller picks the buffer (a shared
    /// memory buffer for a large value, a `Vec` otherwise), so the value is encoded
    /// once, straight where it travels from.
    pub fn encode_with(
        &self,
        from: &DynIn,
        then: &mut dyn FnMut(&Encoder<'_>),
    ) -> Result<(), String> {
        (self.encode_with)(from, then)
    }

    /// [`decode`](Self::decode) from a buffer the caller holds: the value's
    /// [`Bytes`](crate::Bytes) fields keep ranges of `holder` instead of copies.
    pub fn decode_held(&self, to: &DynOut, holder: &Arc<dyn Holder>) -> Result<(), String> {
        bytes::decode_in_place(holder, |b| self.decode(to, b))
    }

    /// [`decode_held`](Self::decode_held) of a value that arrived in pieces, the
    /// buffers `parts` one after the other (a value whose bytes the writer lent,
    /// [`crate::lend`]): `Bytes` fields keep ranges of the part they lie in. A block of
    /// bytes that spans two parts is decoded from a copy of them joined.
    pub fn decode_parts(&self, to: &DynOut, parts: &[Arc<dyn Holder>]) -> Result<(), String> {
        (self.decode_parts)(to, parts)
    }

    /// Decodes `bytes` and publishes the value on `to`. A value that does not decode
    /// (a peer built from another model, a damaged message) is an error, never a panic.
    pub fn decode(&self, to: &DynOut, bytes: &[u8]) -> Result<(), String> {
        (self.decode)(to, bytes)
    }

    /// Parses `bytes` as a value in its JSON (serde) form and publishes it on `to`, or
    /// with `to` = `None` only checks that it parses (`ferroc_std.Const`'s values).
    pub fn from_json(&self, to: Option<&DynOut>, bytes: &[u8]) -> Result<(), String> {
        (self.from_json)(to, bytes)
    }

    /// Replaces `bytes` with the latest value of `from` as JSON (serde's form of the
    /// value, for tools that display recordings). Not exact: JSON has no NaN or
    /// infinity, so serde_json writes non-finite floats as `null`; the postcard form
    /// of [`encode`](Self::encode) is the exact one.
    pub fn json(&self, from: &DynIn, bytes: &mut Vec<u8>) -> Result<(), String> {
        (self.json)(from, bytes)
    }

    /// Replaces `bytes` with the latest value of `from` as a CDR sample of the ROS 2
    /// message `shape` (the whole message, or the one field the port carries).
    pub fn ros2_encode(
        &self,
        from: &DynIn,
        shape: &Shape<'_>,
        bytes: &mut Vec<u8>,
    ) -> Result<(), String> {
        (self.ros2_encode)(from, shape, "", bytes)
    }

    /// [`ros2_encode`](Self::ros2_encode) with the frame the model names for the topic
    /// (`frame-id=`), which a type mapped to a message with a `header`
    /// ([`Ros2Message`](crate::Ros2Message)) writes into it; other types ignore it.
    pub fn ros2_encode_framed(
        &self,
        from: &DynIn,
        shape: &Shape<'_>,
        frame_id: &str,
        bytes: &mut Vec<u8>,
    ) -> Result<(), String> {
        (self.ros2_encode)(from, shape, frame_id, bytes)
    }

    /// Decodes a CDR sample of the ROS 2 message `shape` and publishes the value on
    /// `to`. A sample that does not decode is an error naming the field, never a panic.
    pub fn ros2_decode(&self, to: &DynOut, shape: &Shape<'_>, bytes: &[u8]) -> Result<(), String> {
        (self.ros2_decode)(to, shape, bytes)
    }
}

fn encode<T: PortValue + Serialize>(from: &DynIn, bytes: &mut Vec<u8>) -> Result<(), String> {
    let port = from
        .typed::<T>()
        .ok_or_else(|| format!("`{}` does not carry {}", from.name(), T::model_type()))?;
    let value = port.get();
    bytes.clear();
    let buffer = std::mem::take(bytes);
    *bytes = postcard::to_extend(value.borrow(), buffer).map_err(|e| e.to_string())?;
    Ok(())
}

/// A value ready to be encoded: its encoded size, and how it writes itself into a
/// buffer of that size ([`Codec::encode_with`]).
pub struct Encoder<'a> {
    len: usize,
    write: &'a dyn Fn(&mut [u8]) -> Result<(), String>,
    /// The lent buffers the value holds ([`crate::lend`]), in the order it encodes them.
    lent: Vec<Arc<dyn LentBuffer>>,
    split: Option<&'a SplitFn<'a>>,
    /// The bytes the size pass kept ([`OnePass`]), handed out instead of encoding the
    /// value again: the pieces once, the whole encoding once by value or to copy.
    kept: Cell<Option<Kept>>,
}

/// Encodes a value into pieces around the lent buffers it is handed.
type SplitFn<'a> = dyn Fn(&[Arc<dyn LentBuffer>]) -> Result<Vec<Piece>, String> + 'a;

impl<'a> Encoder<'a> {
    /// An encoder of a value of `len` encoded bytes that `write` writes into a buffer
    /// of that size (for networks' tests; [`Codec::encode_with`] makes the real ones).
    pub fn new(len: usize, write: &'a dyn Fn(&mut [u8]) -> Result<(), String>) -> Self {
        Encoder {
            len,
            write,
            lent: Vec::new(),
            split: None,
            kept: Cell::new(None),
        }
    }

    /// The value as pieces, if it holds buffers an output lent ([`crate::lend`]): each
    /// lent buffer a piece of its own (sent as it is, without a copy), the rest encoded
    /// around them; together exactly the bytes [`write`](Self::write) writes. `None`
    /// for a value without lent buffers.
    pub fn pieces(&self) -> Result<Option<Vec<Piece>>, String> {
        match self.kept.take() {
            Some(Kept::Pieces(pieces)) => return Ok(Some(pieces)),
            other => self.kept.set(other),
        }
        match self.split {
            Some(split) if !self.lent.is_empty() => split(&self.lent).map(Some),
            _ => Ok(None),
        }
    }

    /// The encoded size in bytes.
    #[allow(clippy::len_without_is_empty)] // an encoded value is never empty
    pub fn len(&self) -> usize {
        self.len
    }

    /// Encodes the value into `buffer`, which must be [`len`](Self::len) bytes long.
    pub fn write(&self, buffer: &mut [u8]) -> Result<(), String> {
        if buffer.len() != self.len {
            return Err(format!(
                "a value of {} bytes was to be encoded into a buffer of {}",
                self.len,
                buffer.len()
            ));
        }
        match self.kept.take() {
            Some(Kept::Whole(bytes)) => {
                buffer.copy_from_slice(&bytes);
                self.kept.set(Some(Kept::Whole(bytes)));
                Ok(())
            }
            other => {
                self.kept.set(other);
                (self.write)(buffer)
            }
        }
    }

    /// The value encoded into a new `Vec` of its exact size.
    pub fn to_vec(&self) -> Result<Vec<u8>, String> {
        match self.kept.take() {
            Some(Kept::Whole(bytes)) => return Ok(bytes),
            other => self.kept.set(other),
        }
        let mut bytes = vec![0; self.len];
        self.write(&mut bytes)?;
        Ok(bytes)
    }
}

fn encode_with<T: PortValue + Serialize>(
    from: &DynIn,
    then: &mut dyn FnMut(&Encoder<'_>),
) -> Result<(), String> {
    let port = from
        .typed::<T>()
        .ok_or_else(|| format!("`{}` does not carry {}", from.name(), T::model_type()))?;
    let value = port.get();
    let value: &T = value.borrow();
    // One pass: the size, and the bytes of a small or lent value (see `OnePass`).
    let (passed, lent) =
        bytes::collect_lent(|| postcard::serialize_with_flavor(value, OnePass::new()));
    let passed = passed.map_err(|e| e.to_string())?;
    let write = |buffer: &mut [u8]| {
        postcard::to_slice(value, buffer)
            .map(|_| ())
            .map_err(|e| e.to_string())
    };
    let split = |lent: &[Arc<dyn LentBuffer>]| {
        postcard::serialize_with_flavor(value, Split::new(lent)).map_err(|e| e.to_string())
    };
    then(&Encoder {
        len: passed.len,
        write: &write,
        lent,
        split: Some(&split),
        kept: Cell::new(passed.kept),
    });
    Ok(())
}

fn json<T: PortValue + Serialize>(from: &DynIn, bytes: &mut Vec<u8>) -> Result<(), String> {
    let port = from
        .typed::<T>()
        .ok_or_else(|| format!("`{}` does not carry {}", from.name(), T::model_type()))?;
    let value = port.get();
    bytes.clear();
    serde_json::to_writer(&mut *bytes, value.borrow()).map_err(|e| e.to_string())
}

fn from_json<T: PortValue + DeserializeOwned>(
    to: Option<&DynOut>,
    bytes: &[u8],
) -> Result<(), String> {
    let value: T = serde_json::from_slice(bytes)
        .map_err(|e| format!("not a {} value: {e}", T::model_type()))?;
    if let Some(to) = to {
        let port = to
            .typed::<T>()
            .ok_or_else(|| format!("`{}` does not carry {}", to.name(), T::model_type()))?;
        port.publish(value);
    }
    Ok(())
}

fn ros2_encode<T: PortValue + Serialize>(
    from: &DynIn,
    shape: &Shape<'_>,
    _frame_id: &str,
    bytes: &mut Vec<u8>,
) -> Result<(), String> {
    let port = from
        .typed::<T>()
        .ok_or_else(|| format!("`{}` does not carry {}", from.name(), T::model_type()))?;
    let value = port.get();
    serde_cdr::to_cdr(shape, value.borrow(), bytes).map_err(|e| e.to_string())
}

fn ros2_decode<T: PortValue + DeserializeOwned>(
    to: &DynOut,
    shape: &Shape<'_>,
    bytes: &[u8],
) -> Result<(), String> {
    let value: T = serde_cdr::from_cdr(shape, bytes).map_err(|e| e.to_string())?;
    let port = to
        .typed::<T>()
        .ok_or_else(|| format!("`{}` does not carry {}", to.name(), T::model_type()))?;
    port.publish(value);
    Ok(())
}

fn decode_parts<T: PortValue + DeserializeOwned>(
    to: &DynOut,
    parts: &[Arc<dyn Holder>],
) -> Result<(), String> {
    let value = bytes::decode_in_parts(parts, || {
        let pieces = parts.iter().map(|p| (**p).as_ref()).collect();
        let mut chained = postcard::Deserializer::from_flavor(Chain::new(pieces));
        T::deserialize(&mut chained)
    });
    let value: T = match value {
        Ok(value) => value,
        // A block of bytes across two parts (not as a writer splits): decode a copy.
        Err(_) => {
            let joined: Vec<u8> = parts.iter().flat_map(|p| (**p).as_ref()).copied().collect();
            postcard::from_bytes(&joined)
                .map_err(|e| format!("not a {} value: {e}", T::model_type()))?
        }
    };
    let port = to
        .typed::<T>()
        .ok_or_else(|| format!("`{}` does not carry {}", to.name(), T::model_type()))?;
    port.publish(value);
    Ok(())
}

fn decode<T: PortValue + DeserializeOwned>(to: &DynOut, bytes: &[u8]) -> Result<(), String> {
    let value: T =
        postcard::from_bytes(bytes).map_err(|e| format!("not a {} value: {e}", T::model_type()))?;
    let port = to
        .typed::<T>()
        .ok_or_else(|| format!("`{}` does not carry {}", to.name(), T::model_type()))?;
    port.publish(value);
    Ok(())
}

#[cfg(test)]
mod tests;
