//! The pool's backend: Zenoh's POSIX backend, counting the bytes of the chunks it
//! hands out and takes back. Its own file because it is the one place that sees every
//! chunk come and go (`ferroc inspect`'s pool figures, stats.rs).

use std::sync::atomic::{AtomicUsize, Ordering};
use zenoh::shm::{
    ChunkAllocResult, ChunkDescriptor, MemoryLayout, PosixShmProviderBackend, ProtocolID,
    ShmProvider, ShmProviderBackend, ShmProviderBuilder, WithProtocolID, ZLayoutError,
};
use zenoh::Wait;

/// Zenoh's default POSIX backend, counting the bytes of the chunks it hands out and
/// takes back: what the pool holds now ([`Counting::available`] is the rest; the default
/// backend itself does not say). One atomic add per buffer.
pub struct Counting {
    inner: PosixShmProviderBackend,
    size: usize,
    used: AtomicUsize,
}

impl Counting {
    /// A provider of a pool of `size` bytes on the counting backend.
    pub fn provider(size: usize) -> zenoh::Result<ShmProvider<Counting>> {
        let inner = PosixShmProviderBackend::builder(size).wait()?;
        let backend = Counting {
            inner,
            size,
            used: AtomicUsize::new(0),
        };
        Ok(ShmProviderBuilder::backend(backend).wait())
    }
}

impl WithProtocolID for Counting {
    fn id(&self) -> ProtocolID {
        self.inner.id()
    }
}

impl ShmProviderBackend for Counting {
    fn alloc(&self, layout: &MemoryLayout) -> ChunkAllocResult {
        let chunk = self.inner.alloc(layout);
        if let Ok(c) = &chunk {
            self.used
                .fetch_add(c.descriptor.len.get(), Ordering::Relaxed);
        }
        chunk
    }

    fn free(&self, chunk: &ChunkDescriptor) {
        self.inner.free(chunk);
        self.used.fetch_sub(chunk.len.get(), Ordering::Relaxed);
    }

    fn defragment(&self) -> usize {
        self.inner.defragment()
    }

    fn available(&self) -> usize {
        self.size.saturating_sub(self.used.load(Ordering::Relaxed))
    }

    fn layout_for(&self, layout: MemoryLayout) -> Result<MemoryLayout, ZLayoutError> {
        self.inner.layout_for(layout)
    }
}
