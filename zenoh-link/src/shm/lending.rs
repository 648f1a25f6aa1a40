//! Lending: a buffer of the pool an output fills in place (`Out::lend`,
//! `ferroc_module::lend`), sent without a copy. Its own file because it is the one
//! part of the pool a module touches: what it may write, and when.

use super::Provider;
#[cfg(feature = "shared-memory")]
use super::Reclaim;
use ferroc_runtime::module::lend::LentBuffer;
#[cfg(feature = "shared-memory")]
use std::any::Any;
use zenoh::bytes::ZBytes;
#[cfg(feature = "shared-memory")]
use zenoh::shm::{zshmmut, ZShm};
#[cfg(feature = "shared-memory")]
use zenoh::Wait;

/// A buffer of `len` bytes from `provider`, collecting and defragmenting first if
/// needed; never waits.
#[cfg(feature = "shared-memory")]
pub(super) fn lend_from(provider: &Provider, len: usize) -> Option<Box<dyn LentBuffer>> {
    let buffer = provider.alloc(len).with_policy::<Reclaim>().wait().ok()?;
    Some(Box::new(Lent(buffer.into())))
}

#[cfg(not(feature = "shared-memory"))]
pub(super) fn lend_from(provider: &Provider, _: usize) -> Option<Box<dyn LentBuffer>> {
    match *provider {}
}

/// A pool buffer lent to an output ([`Pool::lend`]).
#[cfg(feature = "shared-memory")]
pub struct Lent(ZShm);

/// Built without shared memory: no buffer is ever lent.
#[cfg(not(feature = "shared-memory"))]
pub enum Lent {}

impl Lent {
    /// The buffer, to send: one more reference, so the module can no longer write it.
    #[cfg(feature = "shared-memory")]
    pub fn shared(&self) -> ZBytes {
        ZBytes::from(self.0.clone())
    }

    #[cfg(not(feature = "shared-memory"))]
    pub fn shared(&self) -> ZBytes {
        match *self {}
    }
}

#[cfg(feature = "shared-memory")]
impl LentBuffer for Lent {
    fn bytes(&self) -> &[u8] {
        &self.0
    }

    fn bytes_mut(&mut self) -> Option<&mut [u8]> {
        // Only while no one else (Zenoh, a reader in any process) holds the buffer.
        let buffer: &mut zshmmut = (&mut self.0).try_into().ok()?;
        Some(&mut buffer[..])
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}
