//! The pool's backend: Zenoh's POSIX backend, counting the bytes of the chunks it
//! hands out and takes back, and knowing each chunk by its address. Its own file
//! because it is the one place that sees every chunk come and go: `ferroc inspect`'s
//! pool figures (stats.rs) and the return of buffers a gone reader held (reclaim.rs).

use std::collections::HashMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use zenoh::shm::{
    ChunkAllocResult, ChunkDescriptor, MemoryLayout, PosixShmProviderBackend, ProtocolID,
    ShmProvider, ShmProviderBackend, ShmProviderBuilder, WithProtocolID, ZLayoutError,
};
use zenoh::Wait;

/// Zenoh's default POSIX backend, counting the bytes of the chunks it hands out and
/// takes back: what the pool holds now ([`Counting::available`] is the rest; the default
/// backend itself does not say). One atomic add and one short lock per buffer.
pub struct Counting {
    chunks: Arc<Chunks>,
}

/// The backend's state, shared with the pool (which frees the chunks of buffers only
/// gone readers hold: [`Chunks::free_held`]).
pub struct Chunks {
    inner: PosixShmProviderBackend,
    size: usize,
    used: AtomicUsize,
    /// Every chunk handed out and not yet taken back, by the address of its first byte
    /// in this process (what a buffer's bytes start at).
    out: Mutex<Out>,
}

#[derive(Default)]
struct Out {
    by_address: HashMap<usize, ChunkDescriptor>,
    address_of: HashMap<(u32, u32), usize>,
}

impl Out {
    fn add(&mut self, address: usize, chunk: &ChunkDescriptor) {
        self.address_of
            .insert((chunk.segment, chunk.chunk), address);
        self.by_address.insert(address, chunk.clone());
    }

    fn remove(&mut self, chunk: &ChunkDescriptor) {
        if let Some(address) = self.address_of.remove(&(chunk.segment, chunk.chunk)) {
            self.by_address.remove(&address);
        }
    }
}

impl Counting {
    /// A provider of a pool of `size` bytes on the counting backend, and the backend's
    /// state.
    pub fn provider(size: usize) -> zenoh::Result<(ShmProvider<Counting>, Arc<Chunks>)> {
        let inner = PosixShmProviderBackend::builder(size).wait()?;
        let chunks = Arc::new(Chunks {
            inner,
            size,
            used: AtomicUsize::new(0),
            out: Mutex::default(),
        });
        let backend = Counting {
            chunks: Arc::clone(&chunks),
        };
        Ok((ShmProviderBuilder::backend(backend).wait(), chunks))
    }
}

impl Chunks {
    /// Gives the chunk whose bytes start at `address` back to the backend although
    /// Zenoh still counts holders of it: only for a buffer whose every holder is gone
    /// (reclaim.rs says why that is sound), and whose Zenoh buffer the caller keeps for
    /// good, so Zenoh never frees the chunk a second time. False if no chunk starts
    /// there.
    pub(crate) fn free_held(&self, address: usize) -> bool {
        let mut out = lock(&self.out);
        let Some(chunk) = out.by_address.get(&address).cloned() else {
            return false;
        };
        out.remove(&chunk);
        drop(out);
        self.inner.free(&chunk);
        self.used.fetch_sub(chunk.len.get(), Ordering::Relaxed);
        true
    }
}

impl WithProtocolID for Counting {
    fn id(&self) -> ProtocolID {
        self.chunks.inner.id()
    }
}

impl ShmProviderBackend for Counting {
    fn alloc(&self, layout: &MemoryLayout) -> ChunkAllocResult {
        let chunks = &self.chunks;
        let chunk = chunks.inner.alloc(layout);
        if let Ok(c) = &chunk {
            chunks
                .used
                .fetch_add(c.descriptor.len.get(), Ordering::Relaxed);
            let address = c.data.ptr() as usize;
            lock(&chunks.out).add(address, &c.descriptor);
        }
        chunk
    }

    fn free(&self, chunk: &ChunkDescriptor) {
        // Forgotten before the backend can hand the same chunk out again.
        let chunks = &self.chunks;
        lock(&chunks.out).remove(chunk);
        chunks.inner.free(chunk);
        chunks.used.fetch_sub(chunk.len.get(), Ordering::Relaxed);
    }

    fn defragment(&self) -> usize {
        self.chunks.inner.defragment()
    }

    fn available(&self) -> usize {
        let chunks = &self.chunks;
        chunks
            .size
            .saturating_sub(chunks.used.load(Ordering::Relaxed))
    }

    fn layout_for(&self, layout: MemoryLayout) -> Result<MemoryLayout, ZLayoutError> {
        self.chunks.inner.layout_for(layout)
    }
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}
