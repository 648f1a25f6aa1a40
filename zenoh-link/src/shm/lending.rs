//! Lending: a buffer of the pool an output fills in place (`Out::lend`,
//! `ferroc_module::lend`), sent without a copy. Its own file because it is the one
//! part of the pool a module touches: what it may write, and when.

#[cfg(feature = "shared-memory")]
use super::reclaim::{address, Ledger};
use super::Provider;
#[cfg(feature = "shared-memory")]
use super::Reclaim;
use ferroc_runtime::module::lend::LentBuffer;
#[cfg(feature = "shared-memory")]
use std::any::Any;
#[cfg(feature = "shared-memory")]
use std::sync::Arc;
use zenoh::bytes::ZBytes;
#[cfg(feature = "shared-memory")]
use zenoh::shm::{zshmmut, ZShm};
#[cfg(feature = "shared-memory")]
use zenoh::Wait;

/// A buffer of `len` bytes from `provider`, collecting and defragmenting first if
/// needed; never waits.
#[cfg(feature = "shared-memory")]
pub(super) fn lend_from(provider: &Provider, len: usize) -> Option<Box<dyn LentBuffer>> {
    let buffer = provider
        .zenoh
        .alloc(len)
        .with_policy::<Reclaim>()
        .wait()
        .ok()?;
    Some(Box::new(Lent {
        buffer: buffer.into(),
        ledger: Arc::clone(&provider.ledger),
        held: Arc::new(()),
    }))
}

#[cfg(not(feature = "shared-memory"))]
pub(super) fn lend_from(provider: &Provider, _: usize) -> Option<Box<dyn LentBuffer>> {
    match *provider {}
}

/// A pool buffer lent to an output ([`Pool::lend`](super::Pool::lend)).
#[cfg(feature = "shared-memory")]
pub struct Lent {
    buffer: ZShm,
    /// The pool's ledger, which lists the buffer once it is sent (reclaim.rs).
    ledger: Arc<Ledger>,
    /// Alive as long as the output holds the buffer: the ledger never gives it back
    /// meanwhile.
    held: Arc<()>,
}

/// Built without shared memory: no buffer is ever lent.
#[cfg(not(feature = "shared-memory"))]
pub enum Lent {}

impl Lent {
    /// The buffer, to send: one more reference, so the module can no longer write it;
    /// listed in the pool's ledger ([`message`](Self::message), then
    /// [`listed`](Self::listed)).
    pub fn shared(&self) -> ZBytes {
        let message = self.message();
        self.listed();
        message
    }

    /// The buffer as a message's bytes: one more reference, so the module can no
    /// longer write it. [`listed`](Self::listed) must follow before the pool hears
    /// that it was sent (`Pool::sent`): a link puts first and lists after, since after
    /// a large fill every line the way to the put touches costs a cache miss. The
    /// buffer stays taken meanwhile: this `Lent` holds it.
    #[cfg(feature = "shared-memory")]
    pub fn message(&self) -> ZBytes {
        ZBytes::from(self.buffer.clone())
    }

    /// [`message`](Self::message) as one slice of a message built slice by slice
    /// (free/pieces.rs); the same rule: [`listed`](Self::listed) follows the put.
    #[cfg(feature = "shared-memory")]
    pub(crate) fn slice(&self) -> zenoh::internal::buffers::ZSlice {
        self.buffer.clone().into()
    }

    /// Lists the buffer in the pool's ledger (who may hold it, reclaim.rs), as held by
    /// its output for as long as this `Lent` lives.
    #[cfg(feature = "shared-memory")]
    pub fn listed(&self) {
        let held = Arc::downgrade(&self.held);
        self.ledger.track(&self.buffer, Some(held));
    }

    #[cfg(not(feature = "shared-memory"))]
    pub fn message(&self) -> ZBytes {
        match *self {}
    }

    #[cfg(not(feature = "shared-memory"))]
    pub fn listed(&self) {
        match *self {}
    }
}

#[cfg(feature = "shared-memory")]
impl LentBuffer for Lent {
    fn bytes(&self) -> &[u8] {
        &self.buffer
    }

    fn bytes_mut(&mut self) -> Option<&mut [u8]> {
        // Only while no one else (Zenoh, a reader in any process) holds the buffer. The
        // ledger's own reference to a sent buffer is taken away to tell, and given back
        // if others still hold it.
        let listed = self.ledger.untrack(address(&self.buffer));
        if <&mut zshmmut>::try_from(&mut self.buffer).is_err() {
            if let Some(record) = listed {
                self.ledger.retrack(&self.buffer, record);
            }
            return None;
        }
        let buffer: &mut zshmmut = (&mut self.buffer).try_into().ok()?;
        Some(&mut buffer[..])
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}
