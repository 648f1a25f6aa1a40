//! [`Bytes`]: the byte buffer of large values (images, point clouds) that a reader in
//! another part reads where it arrived, without copying it out.
//!
//! A value that crosses between parts is decoded from the buffer the network received
//! it in; for a large value on one computer that is a buffer of the writer's shared
//! memory pool. Decoding copies every field out of it, which for a 6 MB image costs more
//! than the whole trip. A `Bytes` field avoids that: while a link's receiving end
//! decodes from a buffer it holds ([`Receiving::decode`]), a `Bytes` whose encoded bytes
//! lie inside that buffer keeps a handle on the buffer and the range instead of a copy.
//! The buffer lives as long as the value (and its clones) does and goes back to its pool
//! when the last one is dropped; until then nobody writes it (the pool only reuses
//! buffers no process holds).
//!
//! Everywhere else a `Bytes` is an ordinary owned `Vec<u8>`: made by a module, decoded
//! from a recording or from a buffer not held this way. Writing to it
//! ([`Bytes::to_mut`]) copies a shared buffer into an owned one first (copy on write), so
//! a writer that fills a pooled port value in place keeps its allocation.
//!
//! A `Bytes` may also be a buffer an output lent its module ([`crate::lend`]): written
//! in place while the value is its only owner, then sent without a copy.
//!
//! No `unsafe`: the check that a borrowed slice lies in the held buffer compares
//! addresses, and the value reads its bytes through the holder's own `AsRef<[u8]>`.

use crate::lend::LentBuffer;
use serde::de::{Error, SeqAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::cell::{Cell, RefCell};
use std::fmt;
use std::ops::{Deref, DerefMut, Range};
use std::sync::Arc;

/// Whatever holds received bytes: a shared-memory buffer, a network buffer, a `Vec`.
pub trait Holder: AsRef<[u8]> + Send + Sync + 'static {}
impl<T: AsRef<[u8]> + Send + Sync + 'static> Holder for T {}

/// A byte buffer that is either owned or a range of a received buffer (see the module
/// documentation). Serialised as one block of bytes: the same postcard form as a
/// `Vec<u8>`.
#[derive(Clone)]
pub struct Bytes(Repr);

#[derive(Clone)]
enum Repr {
    Owned(Vec<u8>),
    Shared {
        holder: Arc<dyn Holder>,
        range: Range<usize>,
    },
    /// A buffer an output lent (see [`crate::lend`]).
    Lent(Arc<dyn LentBuffer>),
}

impl Bytes {
    /// An empty, owned buffer.
    pub const fn new() -> Self {
        Bytes(Repr::Owned(Vec::new()))
    }

    /// The whole of `holder`'s bytes, without a copy.
    pub fn from_holder(holder: Arc<dyn Holder>) -> Self {
        let range = 0..(*holder).as_ref().len();
        Bytes(Repr::Shared { holder, range })
    }

    /// A lent buffer ([`crate::lend`]).
    pub(crate) fn lent(buffer: Box<dyn LentBuffer>) -> Self {
        Bytes(Repr::Lent(Arc::from(buffer)))
    }

    /// The bytes as a `Vec`, to change in place or resize. A buffer read where it
    /// arrived, or a lent one, is first copied into an owned one (the received buffer
    /// is never written; a lent one is written in place through `&mut *bytes`).
    pub fn to_mut(&mut self) -> &mut Vec<u8> {
        if !matches!(self.0, Repr::Owned(_)) {
            self.0 = Repr::Owned(self.as_ref().to_vec());
        }
        match &mut self.0 {
            Repr::Owned(v) => v,
            _ => unreachable!("made owned above"),
        }
    }

    /// Makes it `len` bytes long, new bytes `value` (as `Vec::resize`; owned first).
    pub fn resize(&mut self, len: usize, value: u8) {
        self.to_mut().resize(len, value);
    }

    /// Whether the bytes are read where they arrived (a range of a received buffer)
    /// rather than owned.
    pub fn is_shared(&self) -> bool {
        matches!(self.0, Repr::Shared { .. })
    }

    /// Whether the bytes are a buffer an output lent ([`crate::lend`]).
    pub fn is_lent(&self) -> bool {
        matches!(self.0, Repr::Lent(_))
    }

    /// Whether the bytes can be written in place, without a copy first: owned, or lent
    /// and seen by nobody else yet.
    fn writable_lent(&mut self) -> bool {
        match &mut self.0 {
            Repr::Lent(b) => Arc::get_mut(b).is_some_and(|b| b.bytes_mut().is_some()),
            _ => false,
        }
    }

    /// The bytes as an owned `Vec` (a copy unless they are owned already).
    pub fn into_vec(self) -> Vec<u8> {
        match self.0 {
            Repr::Owned(v) => v,
            Repr::Shared { holder, range } => (*holder).as_ref()[range].to_vec(),
            Repr::Lent(b) => b.bytes().to_vec(),
        }
    }

    /// `bytes` as a range of the buffer this thread decodes from, if they lie in it.
    fn in_received(bytes: &[u8]) -> Option<Bytes> {
        if bytes.is_empty() {
            return None;
        }
        let from = FROM.with(Cell::get);
        RECEIVED.with(|r| {
            r.borrow().get(from..)?.iter().find_map(|holder| {
                let whole = (**holder).as_ref();
                let start = (bytes.as_ptr() as usize).checked_sub(whole.as_ptr() as usize)?;
                let range = start..start.checked_add(bytes.len())?;
                (range.end <= whole.len()).then(|| {
                    Bytes(Repr::Shared {
                        holder: Arc::clone(holder),
                        range,
                    })
                })
            })
        })
    }
}

thread_local! {
    /// The buffers this thread decodes a received value from, while it does: those of
    /// the innermost decode from [`FROM`] on, the outer ones' before. A stack, so that
    /// a decode reuses the list's allocation (one allocation a value fewer in a
    /// network's receive thread).
    static RECEIVED: RefCell<Vec<Arc<dyn Holder>>> = const { RefCell::new(Vec::new()) };
    /// Where the innermost decode's buffers start in [`RECEIVED`].
    static FROM: Cell<usize> = const { Cell::new(0) };
    /// The lent buffers the value this thread encodes holds, while it collects them.
    static LENT: RefCell<Option<Vec<Arc<dyn LentBuffer>>>> = const { RefCell::new(None) };
    /// Where the last of them starts and how long it is ([`lent_now`] compares every
    /// block of bytes with it: most are not lent, and the check must be cheap).
    static LAST_LENT: Cell<(usize, usize)> = const { Cell::new((0, 0)) };
}

/// Runs `decode` on `holder`'s bytes; a [`Bytes`] decoded meanwhile from inside them
/// keeps a range of `holder` instead of a copy. Nested calls restore the outer buffer.
pub fn decode_in_place<R>(holder: &Arc<dyn Holder>, decode: impl FnOnce(&[u8]) -> R) -> R {
    decode_in_parts(std::slice::from_ref(holder), || decode((**holder).as_ref()))
}

/// Runs `decode`; a [`Bytes`] decoded meanwhile from inside one of `holders` keeps a
/// range of it instead of a copy (a value that arrived in pieces). Nested calls
/// restore the outer buffers.
pub fn decode_in_parts<R>(holders: &[Arc<dyn Holder>], decode: impl FnOnce() -> R) -> R {
    /// Puts the outer decode's buffers back (also when `decode` panics).
    struct Restore {
        len: usize,
        from: usize,
    }
    impl Drop for Restore {
        fn drop(&mut self) {
            RECEIVED.with(|r| r.borrow_mut().truncate(self.len));
            FROM.with(|f| f.set(self.from));
        }
    }
    let len = RECEIVED.with(|r| {
        let mut r = r.borrow_mut();
        let len = r.len();
        r.extend(holders.iter().cloned());
        len
    });
    let _restore = Restore {
        len,
        from: FROM.with(|f| f.replace(len)),
    };
    decode()
}

/// Runs `encode` and returns, with its result, the lent buffers of the [`Bytes`] it
/// serialised meanwhile (in their order).
pub(crate) fn collect_lent<R>(encode: impl FnOnce() -> R) -> (R, Vec<Arc<dyn LentBuffer>>) {
    struct Restore(Option<Vec<Arc<dyn LentBuffer>>>);
    impl Drop for Restore {
        fn drop(&mut self) {
            let outer = self.0.take();
            LENT.with(|l| *l.borrow_mut() = outer);
            LAST_LENT.set((0, 0));
        }
    }
    let outer = LENT.with(|l| l.borrow_mut().replace(Vec::new()));
    let restore = Restore(outer);
    LAST_LENT.set((0, 0));
    let result = encode();
    let lent = LENT.with(|l| l.borrow_mut().take()).unwrap_or_default();
    drop(restore);
    (result, lent)
}

/// The lent buffer whose bytes `data` are, if the [`Bytes`] serialised last while
/// [`collect_lent`] runs holds one: an encoder meeting a block of bytes knows at once
/// whether to send it as it is.
pub(crate) fn lent_now(data: &[u8]) -> Option<Arc<dyn LentBuffer>> {
    if data.is_empty() || LAST_LENT.get() != (data.as_ptr() as usize, data.len()) {
        return None;
    }
    LENT.with(|l| {
        let lent = l.borrow();
        let last = lent.as_ref()?.last()?;
        let bytes = last.bytes();
        (bytes.as_ptr() == data.as_ptr() && bytes.len() == data.len()).then(|| Arc::clone(last))
    })
}

impl Default for Bytes {
    fn default() -> Self {
        Bytes::new()
    }
}

impl Deref for Bytes {
    type Target = [u8];
    fn deref(&self) -> &[u8] {
        match &self.0 {
            Repr::Owned(v) => v,
            Repr::Shared { holder, range } => &(**holder).as_ref()[range.clone()],
            Repr::Lent(b) => b.bytes(),
        }
    }
}

/// A lent buffer nobody else sees is written in place; any other buffer not owned
/// (received, or lent and already sent) is copied into an owned one first.
impl DerefMut for Bytes {
    fn deref_mut(&mut self) -> &mut [u8] {
        if !self.writable_lent() {
            return self.to_mut();
        }
        match &mut self.0 {
            Repr::Lent(b) => {
                (Arc::get_mut(b).and_then(|b| b.bytes_mut())).expect("writable_lent checked it")
            }
            _ => unreachable!("writable_lent checked it"),
        }
    }
}

impl AsRef<[u8]> for Bytes {
    fn as_ref(&self) -> &[u8] {
        self
    }
}

impl From<Vec<u8>> for Bytes {
    fn from(v: Vec<u8>) -> Self {
        Bytes(Repr::Owned(v))
    }
}

impl From<&[u8]> for Bytes {
    fn from(v: &[u8]) -> Self {
        Bytes(Repr::Owned(v.to_vec()))
    }
}

impl PartialEq for Bytes {
    fn eq(&self, other: &Self) -> bool {
        **self == **other
    }
}
impl Eq for Bytes {}

impl PartialEq<[u8]> for Bytes {
    fn eq(&self, other: &[u8]) -> bool {
        **self == *other
    }
}

impl PartialEq<Vec<u8>> for Bytes {
    fn eq(&self, other: &Vec<u8>) -> bool {
        **self == **other
    }
}

impl fmt::Debug for Bytes {
    /// The length and where the bytes are, not thousands of numbers.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let where_ = match self.0 {
            Repr::Owned(_) => "owned",
            Repr::Shared { .. } => "received",
            Repr::Lent(_) => "lent",
        };
        write!(f, "Bytes({} bytes, {where_})", self.len())
    }
}

impl Serialize for Bytes {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        if let Repr::Lent(b) = &self.0 {
            LENT.with(|l| {
                if let Some(lent) = l.borrow_mut().as_mut() {
                    lent.push(Arc::clone(b));
                    let bytes = b.bytes();
                    LAST_LENT.set((bytes.as_ptr() as usize, bytes.len()));
                }
            });
        }
        s.serialize_bytes(self)
    }
}

impl<'de> Deserialize<'de> for Bytes {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Bytes, D::Error> {
        d.deserialize_bytes(BytesVisitor)
    }
}

struct BytesVisitor;

impl<'de> Visitor<'de> for BytesVisitor {
    type Value = Bytes;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("bytes")
    }

    fn visit_bytes<E: Error>(self, v: &[u8]) -> Result<Bytes, E> {
        Ok(Bytes::in_received(v).unwrap_or_else(|| v.into()))
    }

    fn visit_byte_buf<E: Error>(self, v: Vec<u8>) -> Result<Bytes, E> {
        Ok(v.into())
    }

    // JSON (recordings' display form) writes bytes as an array of numbers.
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Bytes, A::Error> {
        let mut out = Vec::with_capacity(seq.size_hint().unwrap_or(0).min(1 << 20));
        while let Some(b) = seq.next_element::<u8>()? {
            out.push(b);
        }
        Ok(out.into())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Serialize, Deserialize, PartialEq, Debug)]
    struct Frame {
        name: String,
        data: Bytes,
    }

    fn encoded() -> Vec<u8> {
        let frame = Frame {
            name: "cam".into(),
            data: vec![1, 2, 3, 4].into(),
        };
        postcard::to_stdvec(&frame).unwrap()
    }

    #[test]
    fn decoded_inside_a_held_buffer_it_reads_in_place() {
        let holder: Arc<dyn Holder> = Arc::new(encoded());
        let frame: Frame = decode_in_place(&holder, |b| postcard::from_bytes(b)).unwrap();
        assert!(frame.data.is_shared());
        assert_eq!(frame.data, vec![1, 2, 3, 4]);
        assert_eq!(Arc::strong_count(&holder), 2, "the value keeps the buffer");
        drop(frame);
        assert_eq!(Arc::strong_count(&holder), 1, "and lets it go when dropped");
    }

    #[test]
    fn decoded_elsewhere_it_owns_a_copy() {
        // Bytes outside the held buffer (another slice) are copied, as after the call.
        let holder: Arc<dyn Holder> = Arc::new(vec![0u8; 64]);
        let other = encoded();
        let frame: Frame = decode_in_place(&holder, |_| postcard::from_bytes(&other)).unwrap();
        assert!(!frame.data.is_shared());
        let later: Frame = postcard::from_bytes(&other).unwrap();
        assert!(!later.data.is_shared());
        assert_eq!(frame, later);
        let json = serde_json::to_string(&later).unwrap();
        assert_eq!(serde_json::from_str::<Frame>(&json).unwrap(), later);
    }

    #[test]
    fn a_nested_decode_reads_its_own_buffers_and_gives_the_outer_ones_back() {
        let (outer, inner): (Arc<dyn Holder>, Arc<dyn Holder>) =
            (Arc::new(encoded()), Arc::new(encoded()));
        let (a, b, c) = decode_in_place(&outer, |o| {
            let a: Frame = postcard::from_bytes(o).unwrap();
            // Inside the inner decode the outer buffer is not one of its own.
            let b = decode_in_place(&inner, |_| postcard::from_bytes::<Frame>(o).unwrap());
            let c: Frame = postcard::from_bytes(o).unwrap();
            (a, b, c)
        });
        assert!(
            a.data.is_shared() && c.data.is_shared(),
            "the outer, before and after"
        );
        assert!(!b.data.is_shared(), "not the inner decode's buffer: copied");
        assert_eq!(Arc::strong_count(&outer), 3, "kept by a and c only");
        assert_eq!(Arc::strong_count(&inner), 1, "let go after the decode");
        let after: Frame = postcard::from_bytes(&encoded()).unwrap();
        assert!(
            !after.data.is_shared(),
            "no buffer after the outermost decode"
        );
    }

    #[test]
    fn writing_copies_a_received_buffer_first() {
        let holder: Arc<dyn Holder> = Arc::new(vec![5u8; 8]);
        let mut bytes = Bytes::from_holder(Arc::clone(&holder));
        assert!(bytes.is_shared());
        bytes[0] = 9;
        assert!(!bytes.is_shared());
        assert_eq!(&bytes[..2], &[9, 5]);
        assert_eq!(
            (*holder).as_ref()[0],
            5,
            "the received buffer is never written"
        );
        assert_eq!(Arc::strong_count(&holder), 1);
        assert_eq!(format!("{bytes:?}"), "Bytes(8 bytes, owned)");
    }

    #[test]
    fn the_wire_form_is_that_of_a_byte_vector() {
        let plain = postcard::to_stdvec(&vec![7u8, 8, 9]).unwrap();
        let ours = postcard::to_stdvec(&Bytes::from(vec![7u8, 8, 9])).unwrap();
        assert_eq!(plain, ours);
    }
}
