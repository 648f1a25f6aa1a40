//! A value sent in pieces around a buffer its output lent (`Out::lend`, docs/zenoh.md):
//! one Zenoh message whose lent pool buffer travels as it is (Zenoh sends only its
//! descriptor to a reader on this computer), marked in the attachment, and read back
//! from the buffers as they arrived.

#[cfg(feature = "shared-memory")]
use crate::shm::asking::Read;
use crate::shm::asking::Receipt;
use crate::shm::{Lent, Payload, Pool};
use ferroc_runtime::link::transport::Delivery;
use ferroc_runtime::module::bytes::Holder;
use ferroc_runtime::module::lend::{LentBuffer, Piece};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use zenoh::bytes::ZBytes;

/// The last byte of an attachment (after the link numbers, 4 bytes each) of a value
/// sent in pieces around a lent buffer ([`Encoder::pieces`]).
pub(super) const LENT_MARK: u8 = b'L';

/// One message of a value in `pieces` ([`Encoder::pieces`]): each lent pool buffer
/// as it is (Zenoh sends its descriptor), the encoded bytes around them as they are;
/// and its pool buffers, for the pool's ledger after the put. The slices go straight
/// into the message's buffer list: this runs between a large fill and the put, where
/// every line of code touched is a cache miss (bench/README.md, b4-large).
#[cfg(feature = "shared-memory")]
pub(super) fn joined(pieces: Vec<Piece>) -> (ZBytes, Buffers) {
    use zenoh::internal::buffers::{ZBuf, ZSlice};
    let mut message = ZBuf::empty();
    let mut buffers = Buffers::default();
    for piece in pieces {
        let slice = match piece {
            Piece::Encoded(v) => ZSlice::from(v),
            Piece::Lent(buffer) => match buffer.as_any().downcast_ref::<Lent>() {
                Some(lent) => {
                    let slice = lent.slice();
                    buffers.at.push(Pool::address(buffer.bytes()));
                    buffers.lent.push(buffer);
                    slice
                }
                // Lent by another network (none today): its bytes, copied.
                None => ZSlice::from(buffer.bytes().to_vec()),
            },
        };
        message.push_zslice(slice);
    }
    (ZBytes::from(message), buffers)
}

/// Without shared memory no buffer is a pool's: every piece is copied.
#[cfg(not(feature = "shared-memory"))]
pub(super) fn joined(pieces: Vec<Piece>) -> (ZBytes, Buffers) {
    let mut message = ZBytes::writer();
    for piece in pieces {
        message.append(ZBytes::from(piece.bytes().to_vec()));
    }
    (message.finish(), Buffers::default())
}

/// The pool buffers of a message: where they start, and those an output lent, which
/// the pool's ledger lists after the put ([`Lent::message`]).
#[derive(Default)]
pub(super) struct Buffers {
    pub(super) at: Few<usize>,
    lent: Few<Arc<dyn LentBuffer>>,
}

impl Buffers {
    /// The buffers of a payload the pool filled (none lent: listed already).
    pub(super) fn of(payload: &Payload) -> Buffers {
        Buffers {
            at: Few::Many(Pool::addresses(payload)),
            lent: Few::None,
        }
    }

    /// Lists the lent buffers in the pool's ledger and counts them as sent; after the
    /// put, before `Pool::sent`.
    pub(super) fn listed(&self, pool: Option<&Pool>) {
        for buffer in self.lent.as_slice() {
            if let Some(lent) = buffer.as_any().downcast_ref::<Lent>() {
                lent.listed();
                pool.inspect(|p| p.sent_lent());
            }
        }
    }
}

/// A list that is most often empty or one item long (a message's pool buffers): those
/// need no allocation on the way to the put.
#[derive(Default)]
pub(super) enum Few<T> {
    #[default]
    None,
    One(T),
    Many(Vec<T>),
}

impl<T> Few<T> {
    #[cfg_attr(not(feature = "shared-memory"), allow(dead_code))]
    fn push(&mut self, item: T) {
        *self = match std::mem::take(self) {
            Few::None => Few::One(item),
            Few::One(first) => Few::Many(vec![first, item]),
            Few::Many(mut all) => {
                all.push(item);
                Few::Many(all)
            }
        };
    }

    pub(super) fn as_slice(&self) -> &[T] {
        match self {
            Few::None => &[],
            Few::One(item) => std::slice::from_ref(item),
            Few::Many(all) => all,
        }
    }
}

/// One buffer of a value that arrived in several (a writer's lent buffer and the bytes
/// around it): the message, which keeps them all, and which one.
#[cfg(not(feature = "shared-memory"))]
struct Part(ZBytes, usize);

#[cfg(not(feature = "shared-memory"))]
impl AsRef<[u8]> for Part {
    fn as_ref(&self) -> &[u8] {
        self.0.slices().nth(self.1).unwrap_or_default()
    }
}

/// A slice of a received message kept as it is (a lent buffer in shared memory, read
/// in place).
#[cfg(feature = "shared-memory")]
struct Kept(zenoh::internal::buffers::ZSlice);

#[cfg(feature = "shared-memory")]
impl AsRef<[u8]> for Kept {
    fn as_ref(&self) -> &[u8] {
        self.0.as_slice()
    }
}

/// Slices shorter than this are copied out of the message rather than kept.
#[cfg(feature = "shared-memory")]
const KEEP: usize = 4096;

/// Slices up to this long are copied into a [`Short`].
#[cfg(feature = "shared-memory")]
const SHORT: usize = 128;

/// A short slice copied out of a received message (an image's header), its bytes
/// inline: one allocation (its `Arc`) instead of two for a `Vec`.
#[cfg(feature = "shared-memory")]
struct Short {
    len: u8,
    bytes: [u8; SHORT],
}

#[cfg(feature = "shared-memory")]
impl Short {
    /// A copy of `slice`, if it is at most [`SHORT`] bytes long.
    fn of(slice: &[u8]) -> Option<Short> {
        let len = u8::try_from(slice.len())
            .ok()
            .filter(|l| usize::from(*l) <= SHORT)?;
        let mut bytes = [0; SHORT];
        bytes[..slice.len()].copy_from_slice(slice);
        Some(Short { len, bytes })
    }
}

#[cfg(feature = "shared-memory")]
impl AsRef<[u8]> for Short {
    fn as_ref(&self) -> &[u8] {
        &self.bytes[..usize::from(self.len)]
    }
}

/// The buffers of a value sent in pieces, each as a holder the value may keep. With
/// shared memory: the large slices (a lent pool buffer) as they are, the small ones
/// (the encoded bytes around it) copied. Those small ones lie in Zenoh's receive
/// buffer, of which a link has one to reuse (`transport/link/rx/buffer_size` over the
/// batch size): a value that kept it while its reader holds the value would make Zenoh
/// allocate and zero a new 64 KB buffer for every message (b4-large's reader did).
/// `payload` is taken, not cloned: the message's list of slices is not copied.
pub(super) fn holders(payload: ZBytes, receipt: &Option<Arc<Receipt>>) -> Vec<Arc<dyn Holder>> {
    #[cfg(feature = "shared-memory")]
    {
        let message = zenoh::internal::buffers::ZBuf::from(payload);
        message
            .into_zslices()
            .map(|slice| {
                if slice.len() >= KEEP {
                    return Arc::new(Read::new(Kept(slice), receipt)) as Arc<dyn Holder>;
                }
                match Short::of(slice.as_slice()) {
                    Some(short) => Arc::new(short) as Arc<dyn Holder>,
                    None => Arc::new(slice.as_slice().to_vec()) as Arc<dyn Holder>,
                }
            })
            .collect()
    }
    #[cfg(not(feature = "shared-memory"))]
    let _ = receipt;
    #[cfg(not(feature = "shared-memory"))]
    (0..payload.slices().count())
        .map(|i| Arc::new(Part(payload.clone(), i)) as Arc<dyn Holder>)
        .collect()
}

/// Hands the value of the link `link` that was sent in pieces around a lent buffer,
/// its buffers as they arrived ([`holders`]; the lent one in shared memory from a
/// writer on this computer, read in place), to its receiving end; counted in
/// `received_shared` if this part has shared memory on.
pub(super) fn deliver_pieces(
    delivery: &Delivery,
    received_shared: Option<&AtomicU64>,
    link: u32,
    holders: &[Arc<dyn Holder>],
) {
    if let Some(count) = received_shared {
        count.fetch_add(1, Ordering::Relaxed);
    }
    delivery.deliver_parts(link, holders);
}

#[cfg(all(test, feature = "shared-memory"))]
mod tests {
    use super::*;

    /// A message as a writer sends a lent value: encoded bytes, a large buffer, more
    /// encoded bytes, each its own slice.
    fn message(large: &ZBytes) -> ZBytes {
        let mut message = ZBytes::writer();
        message.append(ZBytes::from(vec![1u8, 2, 3]));
        message.append(large.clone());
        message.append(ZBytes::from(vec![4u8]));
        message.finish()
    }

    #[test]
    fn a_value_in_pieces_keeps_its_large_slice_and_copies_the_bytes_around_it() {
        let large = ZBytes::from(vec![7u8; KEEP]);
        let at = large.slices().next().map(<[u8]>::as_ptr);
        let message = message(&large);
        let holders = holders(message.clone(), &None);
        let parts: Vec<&[u8]> = holders.iter().map(|h| (**h).as_ref()).collect();
        assert_eq!(parts.len(), 3);
        assert_eq!(parts[0], [1, 2, 3]);
        assert_eq!(parts[2], [4]);
        // The large slice is read where it arrived, not copied.
        assert_eq!(Some(parts[1].as_ptr()), at);
        assert_eq!(parts[1], vec![7u8; KEEP]);
        // The small ones are copies: holding the value holds no byte of the message
        // around them (in a received message, Zenoh's receive buffer).
        let small = message.slices().next().map(<[u8]>::as_ptr);
        assert_ne!(Some(parts[0].as_ptr()), small);
    }

    #[test]
    fn a_value_in_small_pieces_is_copied_whole() {
        let message = message(&ZBytes::from(vec![9u8; KEEP - 1]));
        let originals: Vec<*const u8> = message.slices().map(<[u8]>::as_ptr).collect();
        let holders = holders(message.clone(), &None);
        let joined: Vec<u8> = holders
            .iter()
            .flat_map(|h| (**h).as_ref())
            .copied()
            .collect();
        assert_eq!(joined, message.to_bytes().as_ref());
        for (holder, original) in holders.iter().zip(originals) {
            assert_ne!((**holder).as_ref().as_ptr(), original);
        }
    }
}
