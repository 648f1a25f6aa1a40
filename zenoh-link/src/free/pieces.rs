//! A value sent in pieces around a buffer its output lent (`Out::lend`, docs/zenoh.md):
//! one Zenoh message whose lent pool buffer travels as it is (Zenoh sends only its
//! descriptor to a reader on this computer), marked in the attachment, and read back
//! from the buffers as they arrived.

use crate::shm::{Lent, Pool};
use ferroc_runtime::link::transport::Delivery;
use ferroc_runtime::module::bytes::Holder;
use ferroc_runtime::module::lend::Piece;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use zenoh::bytes::ZBytes;

/// The last byte of an attachment (after the link numbers, 4 bytes each) of a value
/// sent in pieces around a lent buffer ([`Encoder::pieces`]).
pub(super) const LENT_MARK: u8 = b'L';

/// One message of a value in `pieces` ([`Encoder::pieces`]): each lent pool buffer
/// as it is (Zenoh sends its descriptor), the encoded bytes around them as they are.
pub(super) fn joined(pool: Option<&Pool>, pieces: Vec<Piece>) -> ZBytes {
    let mut message = ZBytes::writer();
    for piece in pieces {
        let bytes = match piece {
            Piece::Encoded(v) => ZBytes::from(v),
            Piece::Lent(buffer) => match buffer.as_any().downcast_ref::<Lent>() {
                Some(lent) => {
                    pool.inspect(|p| p.sent_lent());
                    lent.shared()
                }
                // Lent by another network (none today): its bytes, copied.
                None => ZBytes::from(buffer.bytes().to_vec()),
            },
        };
        message.append(bytes);
    }
    message.finish()
}

/// One buffer of a value that arrived in several (a writer's lent buffer and the bytes
/// around it): the message, which keeps them all, and which one.
struct Part(ZBytes, usize);

impl AsRef<[u8]> for Part {
    fn as_ref(&self) -> &[u8] {
        self.0.slices().nth(self.1).unwrap_or_default()
    }
}

/// Hands the value `payload` of the link `link`, sent in pieces around a lent buffer,
/// to its receiving end: decoded from the buffers as they arrived (the lent one in
/// shared memory from a writer on this computer, read in place), counted in
/// `received_shared` if this part has shared memory on.
pub(super) fn deliver_pieces(
    delivery: &Delivery,
    received_shared: Option<&AtomicU64>,
    link: u32,
    payload: &ZBytes,
) {
    if let Some(count) = received_shared {
        count.fetch_add(1, Ordering::Relaxed);
    }
    let parts: Vec<Arc<dyn Holder>> = (0..payload.slices().count())
        .map(|i| Arc::new(Part(payload.clone(), i)) as Arc<dyn Holder>)
        .collect();
    delivery.deliver_parts(link, &parts);
}
