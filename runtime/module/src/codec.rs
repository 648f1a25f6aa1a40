//! Values that cross between parts: how a registered value type is encoded.
//!
//! A connection between two parts (two processes, maybe two computers) carries the
//! reader's value type as bytes. The model marks such types `serde="true"`; their
//! crates derive `Serialize`/`Deserialize` and register them with
//! `Registry::register_serde` (`ferroc_app::builder`). The encoding
//! is postcard: compact, and exact for floats (an infinite laser range stays infinite).
//!
//! Like the rest of the value table these are plain function pointers, monomorphised
//! when the type is registered, working on the type-erased [`DynIn`]/[`DynOut`].

use super::value::PortValue;
use super::value_table::{DynIn, DynOut};
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::borrow::Borrow;

/// Encoding and decoding of one value type (an entry of the value table).
#[derive(Clone, Copy)]
pub struct Codec {
    encode: fn(&DynIn, &mut Vec<u8>) -> Result<(), String>,
    decode: fn(&DynOut, &[u8]) -> Result<(), String>,
    json: fn(&DynIn, &mut Vec<u8>) -> Result<(), String>,
    from_json: fn(Option<&DynOut>, &[u8]) -> Result<(), String>,
}

impl Codec {
    /// The functions for `T`.
    pub(crate) fn of<T: PortValue + Serialize + DeserializeOwned>() -> Self {
        Codec {
            encode: encode::<T>,
            decode: decode::<T>,
            json: json::<T>,
            from_json: from_json::<T>,
        }
    }

    /// Replaces `bytes` with the latest value of `from` (made by the same table entry).
    pub fn encode(&self, from: &DynIn, bytes: &mut Vec<u8>) -> Result<(), String> {
        (self.encode)(from, bytes)
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

fn decode<T: PortValue + DeserializeOwned>(to: &DynOut, bytes: &[u8]) -> Result<(), String> {
    let value: T =
        postcard::from_bytes(bytes).map_err(|e| format!("not a {} value: {e}", T::model_type()))?;
    let port = to
        .typed::<T>()
        .ok_or_else(|| format!("`{}` does not carry {}", to.name(), T::model_type()))?;
    port.publish(value);
    Ok(())
}
