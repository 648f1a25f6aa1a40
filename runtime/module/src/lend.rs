//! Lent buffers: an output that hands its module the buffer a large value travels in.
//!
//! A value that goes to another part on the same computer travels in a buffer of the
//! writer's shared-memory pool. Without lending, the module fills a buffer of its own
//! (a [`Bytes`] in process memory) and the link copies it into the pool buffer when it
//! sends the value: for a 6 MB image that copy is most of the trip. With
//! [`Out::lend_in`](crate::Out::lend_in) the module fills the pool buffer itself:
//!
//! ```ignore
//! self.out.publish_with(|image| {
//!     self.out.lend_in(&mut image.data, size); // a pool buffer, or plain memory
//!     camera.read_into(&mut image.data);        // written in place
//! });
//! ```
//!
//! The link then sends the value without copying its bytes: the small fields before
//! and after them are encoded apart (a few bytes), the lent buffer goes as it is
//! ([`Codec::encode_with`](crate::Codec::encode_with) hands the network the pieces,
//! [`Encoder::pieces`](crate::Encoder::pieces)).
//!
//! The buffer is a pool buffer only when the output's only readers are links to other
//! parts and the network has shared memory for them (the builder gives the output a
//! [`Lender`]); otherwise (a reader in the same part, no link, lockstep, shared memory
//! off or unusable, the pool full, a value below the threshold) `lend` returns zeroed
//! plain memory of the same size, so a module never needs to know which it got. A pool
//! buffer is not cleared (that would cost what lending saves): the module writes every
//! byte, as a camera driver filling a frame does. The value behaves as any other:
//! recordings and lockstep encode it as bytes (the same bytes either way).
//!
//! A lent buffer is written only while its [`Bytes`] is its only owner and the
//! buffer has not been handed to the network ([`LentBuffer::bytes_mut`] says so); a
//! write after that copies it into owned memory first, as for a received buffer. So a
//! buffer is never written while a reader, here or in another process, can see it.

use crate::bytes::Bytes;
use std::any::Any;
use std::sync::{Arc, OnceLock};

/// A buffer a network lends an output (a shared-memory pool buffer).
pub trait LentBuffer: Send + Sync + 'static {
    /// Its bytes.
    fn bytes(&self) -> &[u8];
    /// Its bytes to write, if nobody else can see them: not yet handed to the network
    /// (or handed back by every reader). `None` otherwise.
    fn bytes_mut(&mut self) -> Option<&mut [u8]>;
    /// The buffer itself, for the network that lent it to find it again.
    fn as_any(&self) -> &dyn Any;
}

/// Plain memory as a lent buffer, always writable while the output holds it: what a
/// network without a pool may lend, and what tests lend.
impl LentBuffer for Vec<u8> {
    fn bytes(&self) -> &[u8] {
        self
    }
    fn bytes_mut(&mut self) -> Option<&mut [u8]> {
        Some(self)
    }
    fn as_any(&self) -> &dyn Any {
        self
    }
}

/// Lends buffers of `len` bytes: a network whose links carry an output's values.
pub trait Lender: Send + Sync + 'static {
    /// A buffer of exactly `len` bytes, or `None` (the value is small, the pool is
    /// full or there is none): the output then lends plain memory.
    fn lend(&self, len: usize) -> Option<Box<dyn LentBuffer>>;
}

/// Where an output finds its lender: set by the builder when the output feeds a link
/// to another part, empty otherwise.
#[derive(Clone, Default)]
pub struct LendSlot(Arc<OnceLock<Arc<dyn Lender>>>);

impl LendSlot {
    /// Gives the output `lender` (the first one set stays).
    pub fn set(&self, lender: Arc<dyn Lender>) {
        let _ = self.0.set(lender);
    }

    /// Whether a lender is set.
    pub fn is_set(&self) -> bool {
        self.0.get().is_some()
    }

    /// A buffer of `len` bytes: lent if the lender has one (its bytes unspecified: an
    /// earlier value's, maybe), else zeroed plain memory.
    pub fn lend(&self, len: usize) -> Bytes {
        match self.0.get().and_then(|l| l.lend(len)) {
            Some(buffer) if buffer.bytes().len() == len => Bytes::lent(buffer),
            _ => vec![0; len].into(),
        }
    }
}

/// One piece of an encoded value ([`Encoder::pieces`](crate::Encoder::pieces)).
pub enum Piece {
    /// Encoded bytes (the small fields around a lent buffer).
    Encoded(Vec<u8>),
    /// A lent buffer's bytes, exactly, to be sent as they are.
    Lent(Arc<dyn LentBuffer>),
}

impl Piece {
    /// Its bytes.
    pub fn bytes(&self) -> &[u8] {
        match self {
            Piece::Encoded(v) => v,
            Piece::Lent(b) => b.bytes(),
        }
    }
}

impl std::fmt::Debug for Piece {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Piece::Encoded(v) => write!(f, "Encoded({} bytes)", v.len()),
            Piece::Lent(b) => write!(f, "Lent({} bytes)", b.bytes().len()),
        }
    }
}

/// Serialises a value into [`Piece`]s: the bytes of each of `lent` (found by address
/// when the serialiser writes them) become a piece of their own, everything else is
/// encoded around them. Together the pieces are exactly the postcard form.
pub(crate) struct Split<'a> {
    lent: &'a [Arc<dyn LentBuffer>],
    pieces: Vec<Piece>,
    current: Vec<u8>,
}

impl<'a> Split<'a> {
    pub(crate) fn new(lent: &'a [Arc<dyn LentBuffer>]) -> Self {
        Split {
            lent,
            pieces: Vec::new(),
            current: Vec::new(),
        }
    }
}

impl postcard::ser_flavors::Flavor for Split<'_> {
    type Output = Vec<Piece>;

    fn try_push(&mut self, data: u8) -> postcard::Result<()> {
        self.current.push(data);
        Ok(())
    }

    fn try_extend(&mut self, data: &[u8]) -> postcard::Result<()> {
        let lent = (self.lent.iter()).find(|b| {
            let b = b.bytes();
            !b.is_empty() && b.as_ptr() == data.as_ptr() && b.len() == data.len()
        });
        match lent {
            Some(buffer) => {
                if !self.current.is_empty() {
                    let encoded = std::mem::take(&mut self.current);
                    self.pieces.push(Piece::Encoded(encoded));
                }
                self.pieces.push(Piece::Lent(Arc::clone(buffer)));
            }
            None => self.current.extend_from_slice(data),
        }
        Ok(())
    }

    fn finalize(mut self) -> postcard::Result<Vec<Piece>> {
        if !self.current.is_empty() {
            self.pieces.push(Piece::Encoded(self.current));
        }
        Ok(self.pieces)
    }
}

/// How many encoded bytes outside lent buffers [`OnePass`] keeps before it gives up
/// (the shared-memory threshold's default: a value this small is sent as bytes).
pub(crate) const KEPT: usize = 4096;

/// Counts a value's encoded size and, in the same pass, keeps its bytes while they stay
/// within [`KEPT`] outside the lent buffers: as pieces around the lent buffers it
/// meets (the [`Split`] form), or whole for a value without any. A lent value then
/// needs one walk, not a size pass and a pieces pass: after its module filled
/// megabytes the writer's caches hold nothing else, and every line of code and data a
/// walk touches is a miss (bench/README.md, b4-large). A value it could not keep
/// (larger outside lent buffers) is encoded again by the caller, as before.
pub(crate) struct OnePass {
    len: usize,
    /// The bytes since the last lent buffer; `None` once the value outgrew `KEPT`.
    current: Option<Vec<u8>>,
    kept: usize,
    pieces: Vec<Piece>,
}

/// What [`OnePass`] made: the encoded size, and the bytes if it kept them.
pub(crate) struct Passed {
    pub(crate) len: usize,
    pub(crate) kept: Option<Kept>,
}

/// A value's encoded bytes, kept by [`OnePass`].
pub(crate) enum Kept {
    /// No lent buffer: the whole encoding.
    Whole(Vec<u8>),
    /// The pieces around its lent buffers ([`Encoder::pieces`](crate::Encoder::pieces)).
    Pieces(Vec<Piece>),
}

impl OnePass {
    pub(crate) fn new() -> Self {
        OnePass {
            len: 0,
            current: Some(Vec::with_capacity(64)),
            kept: 0,
            pieces: Vec::new(),
        }
    }

    /// Keeps `data` if there is room, else stops keeping anything.
    fn keep(&mut self, data: &[u8]) {
        let Some(current) = &mut self.current else {
            return;
        };
        if self.kept + data.len() <= KEPT {
            current.extend_from_slice(data);
            self.kept += data.len();
        } else {
            self.current = None;
            self.pieces = Vec::new();
        }
    }
}

impl postcard::ser_flavors::Flavor for OnePass {
    type Output = Passed;

    fn try_push(&mut self, data: u8) -> postcard::Result<()> {
        self.len += 1;
        self.keep(&[data]);
        Ok(())
    }

    fn try_extend(&mut self, data: &[u8]) -> postcard::Result<()> {
        self.len += data.len();
        let Some(current) = &mut self.current else {
            return Ok(());
        };
        match crate::bytes::lent_now(data) {
            Some(buffer) => {
                if !current.is_empty() {
                    self.pieces.push(Piece::Encoded(std::mem::take(current)));
                }
                self.pieces.push(Piece::Lent(buffer));
            }
            None => self.keep(data),
        }
        Ok(())
    }

    fn finalize(mut self) -> postcard::Result<Passed> {
        let kept = self.current.map(|current| {
            if self.pieces.is_empty() {
                return Kept::Whole(current);
            }
            if !current.is_empty() {
                self.pieces.push(Piece::Encoded(current));
            }
            Kept::Pieces(self.pieces)
        });
        Ok(Passed {
            len: self.len,
            kept,
        })
    }
}

/// Deserialises from several buffers one after the other (a value that arrived in
/// pieces). A block of bytes must lie within one buffer, as the writer's pieces do;
/// one that spans two is an error (the caller then joins the buffers and decodes
/// the copy).
pub(crate) struct Chain<'de> {
    parts: Vec<&'de [u8]>,
    /// The buffer read now, and how far.
    part: usize,
    at: usize,
}

impl<'de> Chain<'de> {
    pub(crate) fn new(parts: Vec<&'de [u8]>) -> Self {
        Chain {
            parts,
            part: 0,
            at: 0,
        }
    }

    /// Moves past buffers read to their end; the bytes left in the current one.
    fn current(&mut self) -> &'de [u8] {
        while let Some(part) = self.parts.get(self.part) {
            if self.at < part.len() {
                return &part[self.at..];
            }
            self.part += 1;
            self.at = 0;
        }
        &[]
    }
}

impl<'de> postcard::de_flavors::Flavor<'de> for Chain<'de> {
    type Remainder = ();
    type Source = ();

    fn pop(&mut self) -> postcard::Result<u8> {
        let byte = *(self.current().first()).ok_or(postcard::Error::DeserializeUnexpectedEnd)?;
        self.at += 1;
        Ok(byte)
    }

    fn try_take_n(&mut self, ct: usize) -> postcard::Result<&'de [u8]> {
        if ct == 0 {
            return Ok(&[]);
        }
        let here = self.current();
        let taken = here
            .get(..ct)
            .ok_or(postcard::Error::DeserializeUnexpectedEnd)?;
        self.at += ct;
        Ok(taken)
    }

    fn finalize(self) -> postcard::Result<()> {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bytes::{collect_lent, decode_in_parts, Holder};
    use serde::{Deserialize, Serialize};
    use std::sync::Mutex;

    /// A lent buffer in plain memory that counts as handed to a network while anyone
    /// holds a clone of `sent`.
    struct Fake {
        bytes: Vec<u8>,
        sent: Arc<()>,
    }
    impl LentBuffer for Fake {
        fn bytes(&self) -> &[u8] {
            &self.bytes
        }
        fn bytes_mut(&mut self) -> Option<&mut [u8]> {
            (Arc::strong_count(&self.sent) == 1).then_some(&mut self.bytes[..])
        }
        fn as_any(&self) -> &dyn Any {
            self
        }
    }

    /// Lends buffers of at least 16 bytes; keeps the last one's `sent`.
    #[derive(Default)]
    struct FakeLender(Mutex<Option<Arc<()>>>);
    impl Lender for FakeLender {
        fn lend(&self, len: usize) -> Option<Box<dyn LentBuffer>> {
            let sent = Arc::new(());
            *self.0.lock().unwrap() = Some(Arc::clone(&sent));
            let fake = Fake {
                bytes: vec![0; len],
                sent,
            };
            (len >= 16).then(|| Box::new(fake) as Box<dyn LentBuffer>)
        }
    }

    #[derive(Serialize, Deserialize, PartialEq, Debug)]
    struct Frame {
        name: String,
        data: Bytes,
        tail: u32,
    }

    fn lending() -> (LendSlot, Arc<FakeLender>) {
        let slot = LendSlot::default();
        let lender = Arc::new(FakeLender::default());
        slot.set(Arc::clone(&lender) as Arc<dyn Lender>);
        (slot, lender)
    }

    #[test]
    fn without_a_lender_or_with_a_refusal_an_output_lends_plain_memory() {
        let plain = LendSlot::default();
        assert!(!plain.is_set());
        let bytes = plain.lend(32);
        assert!(!bytes.is_lent() && bytes.len() == 32 && bytes.iter().all(|b| *b == 0));
        let (slot, _) = lending();
        assert!(!slot.lend(8).is_lent(), "the lender refused: plain memory");
        assert_eq!(slot.lend(8).len(), 8);
    }

    #[test]
    fn a_lent_buffer_is_written_in_place_and_travels_in_pieces_around_it() {
        let (slot, lender) = lending();
        let mut data = slot.lend(32);
        *lender.0.lock().unwrap() = None; // not sent
        data[..4].copy_from_slice(&[1, 2, 3, 4]);
        assert!(data.is_lent(), "written in place, not copied");
        let frame = Frame {
            name: "cam".into(),
            data,
            tail: 9,
        };
        let (size, lent) = collect_lent(|| postcard::experimental::serialized_size(&frame));
        assert_eq!(lent.len(), 1);
        let pieces = postcard::serialize_with_flavor(&frame, Split::new(&lent)).unwrap();
        assert!(matches!(
            pieces.as_slice(),
            [Piece::Encoded(_), Piece::Lent(_), Piece::Encoded(_)]
        ));
        let joined: Vec<u8> = pieces.iter().flat_map(|p| p.bytes()).copied().collect();
        let whole = postcard::to_stdvec(&frame).unwrap();
        assert_eq!(joined, whole, "the pieces are the postcard form");
        assert_eq!(size.unwrap(), whole.len());
        // Decoded from the pieces as they arrive: the bytes read in place.
        let parts: Vec<Arc<dyn Holder>> = (pieces.iter())
            .map(|p| Arc::new(p.bytes().to_vec()) as Arc<dyn Holder>)
            .collect();
        let back: postcard::Result<Frame> = decode_in_parts(&parts, || {
            let chain = Chain::new(parts.iter().map(|p| (**p).as_ref()).collect());
            Frame::deserialize(&mut postcard::Deserializer::from_flavor(chain))
        });
        let back = back.unwrap();
        assert_eq!(back, frame);
        assert!(back.data.is_shared(), "read where it arrived");
        // A block of bytes across two parts is an error (the caller joins them).
        let (a, b) = whole.split_at(whole.len() - 10);
        let mut split = postcard::Deserializer::from_flavor(Chain::new(vec![a, b]));
        assert!(Frame::deserialize(&mut split).is_err());
    }

    #[test]
    fn a_lent_buffer_anyone_else_sees_is_copied_before_a_write() {
        let (slot, lender) = lending();
        // Held by a clone (a reader in this part): the writer's bytes are copied first.
        let mut data = slot.lend(32);
        *lender.0.lock().unwrap() = None;
        let reader = data.clone();
        data[0] = 5;
        assert!(!data.is_lent() && reader.is_lent());
        assert_eq!(
            (data[0], reader[0]),
            (5, 0),
            "the reader's bytes did not change"
        );
        // Handed to the network: the same.
        let mut data = slot.lend(32);
        let sent = lender.0.lock().unwrap().clone();
        data[0] = 6;
        assert!(
            !data.is_lent(),
            "copied: the network still holds the buffer"
        );
        drop(sent);
        let mut data = slot.lend(32);
        *lender.0.lock().unwrap() = None;
        data[0] = 7;
        assert!(data.is_lent(), "nobody else holds it: written in place");
        assert_eq!(format!("{data:?}"), "Bytes(32 bytes, lent)");
        assert_eq!(data.clone().into_vec()[0], 7);
    }
}
