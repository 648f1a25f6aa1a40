//! Shared memory for links between parts on one computer.
//!
//! A part that sends values across parts owns one bounded pool of POSIX shared memory
//! (Zenoh's `ShmProvider` on its POSIX backend). A value whose encoding is at least
//! the threshold goes into a buffer of that pool; Zenoh then sends only the buffer's
//! descriptor to a reader on the same computer, which maps the buffer and decodes the
//! value straight from it. A reader on another computer (or one whose session has
//! shared memory off) gets the bytes over the network: Zenoh decides per peer, the
//! model does not change. Smaller values take the network path as before.
//!
//! Both numbers are Zenoh's own settings (docs/zenoh.md), so `--zenoh-config` changes
//! them: `transport/shared_memory/transport_optimization/message_size_threshold`
//! (ferroc's default 4096 bytes) and `…/pool_size` (ferroc's default 64 MiB, ten 1080p
//! RGB frames); `transport/shared_memory/enabled: false` turns shared memory off.
//!
//! A buffer is never written while a reader can still see it: a buffer handed to Zenoh
//! is immutable (`ZShmMut` becomes `ZBytes`), and the pool only reuses a buffer whose
//! reference count, kept in shared memory by every process that maps it and by Zenoh for
//! buffers still on their way to a peer, is zero (the *safe* garbage collection), or
//! whose every holder's process is gone (a reader killed while it held values:
//! `reclaim.rs`, with the argument why a live reader never loses a buffer).
//!
//! An output whose only readers are links to other parts may lend its module a buffer
//! of the pool to fill ([`Pool::lend`], `ferroc_module::lend`): the value then goes
//! without any copy on the writer's side, the lent buffer as it is, the few bytes of
//! the value's other fields in front of (and after) it as small pieces of the same
//! message. Zenoh sends the buffer's descriptor; the reader decodes from both pieces,
//! reading the buffer in place. The module writes a lent buffer only while nothing
//! else holds it (Zenoh's reference count says it is unique); once sent it is
//! immutable and comes back to the pool as any other.
//!
//! A full pool follows the link's `on-full` policy: a link that may drop values drops
//! the value (a throttled warning); a reliable link waits for buffers to come back,
//! collecting and defragmenting, and after [`BLOCK_LIMIT`] sends that value over the
//! network instead, so it is never lost and the writer never hangs on a reader that
//! stopped reading. A computer without usable shared memory (no `/dev/shm`, a
//! container without it) runs on the network path after one warning.
//!
//! Without the crate's feature `shared-memory` (a bundle whose linked parts share no
//! computer turns it off: Zenoh's shared memory is 21 crates), there is never a pool:
//! every value takes the network path, with the same API and no warning.
//!
//! The pool's parts, each in its own file along the seams where they meet: this file
//! decides where a value goes (settings, the pool, its figures); `lending.rs` is the
//! buffer a module writes; `counting.rs` is the backend that sees every chunk come and
//! go; `reclaim.rs` gives back the buffers of readers that are gone (a reader killed
//! while it held values), `process.rs` tells whether a session's process is gone and
//! `asking.rs` asks live readers which buffers they still hold; `probe.rs` finds a
//! computer without usable shared memory before a session opens; the tests are in
//! `tests.rs`.

pub(crate) mod asking;
#[cfg(feature = "shared-memory")]
mod counting;
mod lending;
pub(crate) mod probe;
pub mod process;
#[cfg(feature = "shared-memory")]
mod reclaim;

#[cfg(feature = "shared-memory")]
use counting::Chunks;
#[cfg(feature = "shared-memory")]
pub use counting::Counting;
use ferroc_runtime::console;
use ferroc_runtime::module::lend::LentBuffer;
use ferroc_runtime::module::Encoder;
use lending::lend_from;
pub use lending::Lent;
#[cfg(feature = "shared-memory")]
use reclaim::Ledger;
#[cfg(feature = "shared-memory")]
pub use reclaim::GRACE;
use std::sync::atomic::{AtomicU64, Ordering};
#[cfg(feature = "shared-memory")]
use std::sync::{Arc, Mutex};
use std::time::Duration;
use zenoh::bytes::ZBytes;
#[cfg(feature = "shared-memory")]
use zenoh::sample::SampleKind;
#[cfg(feature = "shared-memory")]
use zenoh::session::TransportEventsListener;
#[cfg(feature = "shared-memory")]
use zenoh::shm::{Defragment, GarbageCollect, JustAlloc, ShmProvider, ZShm, ZShmMut};
#[cfg(feature = "shared-memory")]
use zenoh::Wait;

/// ferroc's default threshold: values of at least this many encoded bytes travel in
/// shared memory (dora's choice; below it a copy costs less than the bookkeeping).
pub const THRESHOLD: usize = 4096;

/// ferroc's default pool: 64 MiB, room for ten 1080p RGB frames (6.2 MB) on their way.
pub const POOL_SIZE: usize = 64 * 1024 * 1024;

/// How long a reliable link waits for room in a full pool before it sends the value
/// over the network instead.
pub const BLOCK_LIMIT: Duration = Duration::from_millis(500);

const ENABLED_KEY: &str = "transport/shared_memory/enabled";
const THRESHOLD_KEY: &str = "transport/shared_memory/transport_optimization/message_size_threshold";
const POOL_KEY: &str = "transport/shared_memory/transport_optimization/pool_size";

/// The shared-memory settings of a part, read from its Zenoh configuration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Settings {
    /// `transport/shared_memory/enabled`.
    pub enabled: bool,
    /// Values of at least this many encoded bytes go into the pool.
    pub threshold: usize,
    /// The pool's size in bytes.
    pub pool_size: usize,
}

impl Settings {
    /// The settings `config` holds (ferroc's defaults unless a file set them).
    pub fn of(config: &zenoh::Config) -> Settings {
        let number = |key: &str, default: usize| {
            config
                .get_json(key)
                .ok()
                .and_then(|v| v.trim().parse::<usize>().ok())
                .unwrap_or(default)
        };
        Settings {
            enabled: config
                .get_json(ENABLED_KEY)
                .is_ok_and(|v| v.trim() == "true"),
            threshold: number(THRESHOLD_KEY, THRESHOLD),
            pool_size: number(POOL_KEY, POOL_SIZE),
        }
    }
}

/// How a value went out.
#[derive(Debug)]
pub enum Payload {
    /// In a buffer of the pool.
    Shared(ZBytes),
    /// As plain bytes (small, no pool, or a reliable link that waited too long).
    Network(ZBytes),
    /// Not at all: the pool is full and the link drops values.
    Dropped,
}

/// Where a value goes ([`Pool::room`]). (Without shared memory only `Network`.)
#[cfg_attr(not(feature = "shared-memory"), allow(dead_code))]
enum Room {
    #[cfg(feature = "shared-memory")]
    Buffer(ZShmMut),
    Network,
    Dropped,
}

/// What the pool did so far, for `ferroc inspect`, the tests and the benchmarks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Use {
    /// Whether the pool exists (shared memory enabled and usable).
    pub active: bool,
    /// Its size in bytes.
    pub pool_size: usize,
    /// Values sent in shared memory.
    pub shared: u64,
    /// Of those, values whose bytes a module wrote into a buffer its output lent
    /// ([`Pool::lend`]), sent without a copy.
    pub lent: u64,
    /// Values at or above the threshold sent over the network (a full pool on a
    /// reliable link, or a value larger than the pool).
    pub network: u64,
    /// Values dropped because the pool was full.
    pub dropped: u64,
    /// Values this part received in shared memory (from any writer).
    pub received_shared: u64,
    /// Buffers given back although readers still counted in them, the processes of
    /// every session they were sent to being gone (a reader killed while it held
    /// values: reclaim.rs).
    pub reclaimed: u64,
    /// Buffers sent to a reader whose process is gone that have not come back yet:
    /// within the grace, waiting for the other readers' word, or also sent to a session
    /// that cannot answer (reclaim.rs, asking.rs).
    pub gone_held: u64,
}

/// The shared-memory pool of one part (see the module documentation).
pub struct Pool {
    provider: Option<Provider>,
    settings: Settings,
    shared: AtomicU64,
    lent: AtomicU64,
    network: AtomicU64,
    dropped: AtomicU64,
}

/// Zenoh's pool on POSIX shared memory (its backend counting what it holds, for
/// `ferroc inspect`), with the ledger that gives back the buffers of gone readers.
#[cfg(feature = "shared-memory")]
struct Provider {
    zenoh: ShmProvider<Counting>,
    chunks: Arc<Chunks>,
    ledger: Arc<Ledger>,
    /// Zenoh's transport events of the session the part sends with, for the ledger.
    events: Mutex<Option<TransportEventsListener<()>>>,
    /// That session and the key its readers answer on (asking.rs).
    asking: Mutex<Option<(zenoh::Session, zenoh::key_expr::OwnedKeyExpr)>>,
}

/// Built without the feature `shared-memory`: there is no pool to hold.
#[cfg(not(feature = "shared-memory"))]
enum Provider {}

/// Collects buffers no reader holds, then defragments, before giving up on a size.
#[cfg(feature = "shared-memory")]
type Reclaim = Defragment<GarbageCollect<JustAlloc, JustAlloc>>;

/// Zenoh's pool of `settings`, or `None` (after one warning) where the system cannot
/// provide it.
#[cfg(feature = "shared-memory")]
fn provider(settings: Settings) -> Option<Provider> {
    match Counting::provider(settings.pool_size) {
        Ok((zenoh, chunks)) => Some(Provider {
            zenoh,
            chunks,
            ledger: Arc::default(),
            events: Mutex::default(),
            asking: Mutex::default(),
        }),
        Err(e) => {
            probe::warn_unusable(
                &ferroc_terminal::engine_error(&e),
                settings.pool_size,
                probe::PARTS,
            );
            None
        }
    }
}

/// Built without shared memory: never a pool, silently (the bundle chose it).
#[cfg(not(feature = "shared-memory"))]
fn provider(_: Settings) -> Option<Provider> {
    None
}

impl Pool {
    /// The pool `settings` ask for; without usable shared memory, none, after one
    /// warning naming the cause.
    pub fn open(settings: Settings) -> Pool {
        let provider = if settings.enabled {
            provider(settings)
        } else {
            None
        };
        Pool {
            provider,
            settings,
            shared: AtomicU64::new(0),
            lent: AtomicU64::new(0),
            network: AtomicU64::new(0),
            dropped: AtomicU64::new(0),
        }
    }

    /// The payload for `bytes` on a link that must not drop values (`reliable`) or
    /// may: a copy in a pool buffer when they are large enough.
    pub fn payload(&self, bytes: Vec<u8>, reliable: bool, link: &str) -> Payload {
        match self.room(bytes.len(), reliable, link) {
            #[cfg(feature = "shared-memory")]
            Room::Buffer(mut buffer) => {
                buffer.copy_from_slice(&bytes);
                self.shared_payload(buffer)
            }
            Room::Network => Payload::Network(bytes.into()),
            Room::Dropped => Payload::Dropped,
        }
    }

    /// [`payload`](Self::payload) for a value not encoded yet: a large one is encoded
    /// straight into its pool buffer (the only copy on the writer's side), a small one
    /// into a `Vec` of its exact size.
    pub fn payload_encoded(
        &self,
        encoder: &Encoder<'_>,
        reliable: bool,
        link: &str,
    ) -> Result<Payload, String> {
        Ok(match self.room(encoder.len(), reliable, link) {
            #[cfg(feature = "shared-memory")]
            Room::Buffer(mut buffer) => {
                encoder.write(&mut buffer)?;
                self.shared_payload(buffer)
            }
            Room::Network => Payload::Network(encoder.to_vec()?.into()),
            Room::Dropped => Payload::Dropped,
        })
    }

    /// Where a value of `len` encoded bytes goes: a buffer of the pool, the network
    /// (small, no pool, larger than the pool, or a full pool on a reliable link after
    /// [`BLOCK_LIMIT`]), or nowhere (a full pool on a link that drops values).
    fn room(&self, len: usize, reliable: bool, link: &str) -> Room {
        let Some(provider) = self.provider.as_ref() else {
            return Room::Network;
        };
        if len < self.settings.threshold.max(1) {
            return Room::Network;
        }
        if len > self.settings.pool_size {
            self.network.fetch_add(1, Ordering::Relaxed);
            console::note_repeated(&format!(
                "warning: {link}: a value of {len} bytes is larger than the shared-memory pool \
                 ({} bytes); it travels over the network. help: raise \
                 transport/shared_memory/transport_optimization/pool_size in --zenoh-config",
                self.settings.pool_size
            ));
            return Room::Network;
        }
        self.alloc(provider, len, reliable, link)
    }

    /// A buffer of `len` bytes from the pool, else the network or nowhere, as
    /// [`Self::room`] says.
    #[cfg(feature = "shared-memory")]
    fn alloc(&self, provider: &Provider, len: usize, reliable: bool, link: &str) -> Room {
        let started = std::time::Instant::now();
        loop {
            let mut buffer = provider.zenoh.alloc(len).with_policy::<Reclaim>().wait();
            if buffer.is_err() && provider.reclaim() > 0 {
                buffer = provider.zenoh.alloc(len).with_policy::<Reclaim>().wait();
            }
            match buffer {
                Ok(buffer) => {
                    self.shared.fetch_add(1, Ordering::Relaxed);
                    return Room::Buffer(buffer);
                }
                Err(_) if !reliable => {
                    self.dropped.fetch_add(1, Ordering::Relaxed);
                    console::note_repeated(&format!(
                        "warning: {link}: the shared-memory pool is full (readers hold its \
                         buffers); values are dropped (on-full=\"drop\"). help: raise \
                         transport/shared_memory/transport_optimization/pool_size in \
                         --zenoh-config, or make the readers keep up"
                    ));
                    return Room::Dropped;
                }
                Err(_) if started.elapsed() >= BLOCK_LIMIT => {
                    self.network.fetch_add(1, Ordering::Relaxed);
                    console::note_repeated(&format!(
                        "warning: {link}: the shared-memory pool stayed full for {} ms; the \
                         value travels over the network. help: raise \
                         transport/shared_memory/transport_optimization/pool_size in \
                         --zenoh-config, or make the readers keep up",
                        BLOCK_LIMIT.as_millis()
                    ));
                    return Room::Network;
                }
                Err(_) => std::thread::sleep(Duration::from_millis(1)),
            }
        }
    }

    #[cfg(not(feature = "shared-memory"))]
    fn alloc(&self, provider: &Provider, _: usize, _: bool, _: &str) -> Room {
        match *provider {}
    }

    /// A buffer of `len` bytes lent to an output to fill (see the module
    /// documentation), if the value belongs in shared memory (at least the threshold,
    /// not larger than the pool) and the pool has room now; never waits. `None` makes
    /// the output lend plain memory, which the send path then treats as any value.
    pub fn lend(&self, len: usize) -> Option<Box<dyn LentBuffer>> {
        let provider = self.provider.as_ref()?;
        if len < self.settings.threshold.max(1) || len > self.settings.pool_size {
            return None;
        }
        lend_from(provider, len).or_else(|| retry(provider).then(|| lend_from(provider, len))?)
    }

    /// Counts a value sent in a lent buffer.
    pub(crate) fn sent_lent(&self) {
        self.shared.fetch_add(1, Ordering::Relaxed);
        self.lent.fetch_add(1, Ordering::Relaxed);
    }

    /// What the pool did so far.
    pub fn usage(&self) -> Use {
        Use {
            active: self.provider.is_some(),
            pool_size: self.settings.pool_size,
            shared: self.shared.load(Ordering::Relaxed),
            lent: self.lent.load(Ordering::Relaxed),
            network: self.network.load(Ordering::Relaxed),
            dropped: self.dropped.load(Ordering::Relaxed),
            received_shared: 0,
            reclaimed: given_back(self.provider.as_ref()).0,
            gone_held: given_back(self.provider.as_ref()).1,
        }
    }
}

impl Pool {
    /// The pool's size, the bytes held now (by values on their way or read in place;
    /// buffers nobody holds are collected first) and the threshold; `None` without a
    /// pool. For `ferroc inspect` ([`crate::stats`]).
    pub fn held(&self) -> Option<(usize, usize, usize)> {
        let provider = self.provider.as_ref()?;
        retry(provider);
        let size = self.settings.pool_size;
        let used = size.saturating_sub(free_after_collecting(provider));
        Some((size, used, self.settings.threshold))
    }

    /// How many buffers of `size` bytes the pool holds now, after collecting the
    /// buffers no reader holds: a measure of what came back, for checks while nothing
    /// is sent (the probe takes them all for a moment). `None` without a pool.
    pub fn room_for(&self, size: usize) -> Option<usize> {
        self.provider.as_ref().map(|p| {
            retry(p);
            buffers_of(p, size)
        })
    }
}

/// Who may hold the buffers this part sends (reclaim.rs): the session it sends with.
impl Pool {
    /// The part sends with `session` from now on: the ledger follows its transports,
    /// and asks its readers on `held` (`ferroc/APP/held/PART`, asking.rs). Without
    /// Zenoh's transport events it cannot tell who holds a buffer, and gives nothing
    /// back that others hold.
    pub(crate) fn attach(&self, session: &zenoh::Session, held: zenoh::key_expr::OwnedKeyExpr) {
        #[cfg(feature = "shared-memory")]
        if let Some(provider) = &self.provider {
            provider.ledger.attach();
            *lock(&provider.asking) = Some((session.clone(), held));
            let ledger = Arc::clone(&provider.ledger);
            let listener = (session.info().transport_events_listener())
                .history(true)
                .callback(move |event| {
                    let open = event.kind() == SampleKind::Put;
                    let peer = event.transport().zid().to_string();
                    ledger.transport(peer, open, std::time::Instant::now());
                })
                .wait();
            if listener.is_err() {
                provider.ledger.detach();
            }
            *lock(&provider.events) = listener.ok();
        }
        #[cfg(not(feature = "shared-memory"))]
        let _ = (session, held);
    }

    /// The part closed the session it sent with.
    pub(crate) fn detach(&self) {
        #[cfg(feature = "shared-memory")]
        if let Some(provider) = &self.provider {
            provider.ledger.detach();
            lock(&provider.events).take();
            lock(&provider.asking).take();
        }
    }

    /// Where the buffers of `payload` start (to tell [`sent`](Self::sent) after the
    /// put, which takes the payload).
    pub(crate) fn addresses(payload: &Payload) -> Vec<usize> {
        match payload {
            #[cfg(feature = "shared-memory")]
            Payload::Shared(bytes) => bytes.slices().map(Pool::address).collect(),
            _ => Vec::new(),
        }
    }

    /// Where the buffer `bytes` starts: its name in the pool's ledger.
    #[cfg_attr(not(feature = "shared-memory"), allow(dead_code))] // lent buffers only
    pub(crate) fn address(bytes: &[u8]) -> usize {
        bytes.as_ptr() as usize
    }

    /// The buffers at `addresses` were just put, stamped `send` (publisher, number;
    /// asking.rs): the ledger notes who may hold them, and gives back what gone
    /// readers held.
    pub(crate) fn sent(&self, addresses: &[usize], send: Option<(u32, u32)>) {
        #[cfg(feature = "shared-memory")]
        if let (Some(provider), false) = (&self.provider, addresses.is_empty()) {
            provider.ledger.sent(addresses, send);
            provider.reclaim();
        }
        #[cfg(not(feature = "shared-memory"))]
        let _ = (addresses, send);
    }

    /// A filled pool buffer, listed in the ledger, as the payload to send.
    #[cfg(feature = "shared-memory")]
    fn shared_payload(&self, buffer: ZShmMut) -> Payload {
        let buffer = ZShm::from(buffer);
        if let Some(provider) = &self.provider {
            provider.ledger.track(&buffer, None);
        }
        Payload::Shared(buffer.into())
    }
}

#[cfg(feature = "shared-memory")]
impl Provider {
    /// Gives back the buffers only the ledger holds and those only gone readers hold
    /// (reclaim.rs); how many. Asks the live readers what they hold if a buffer waits
    /// for their word (asking.rs).
    fn reclaim(&self) -> usize {
        let now = std::time::Instant::now();
        let back = self.ledger.reclaim(now, &self.chunks);
        if let Some(asked) = self.ledger.to_ask(now) {
            let to = lock(&self.asking).clone();
            match to {
                Some((session, key)) => asking::ask(&session, &key, &self.ledger, asked),
                None => self.ledger.asked(),
            }
        }
        back
    }
}

#[cfg(feature = "shared-memory")]
fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// How many buffers came back from gone readers so far, and how many gone readers
/// still count in.
#[cfg(feature = "shared-memory")]
fn given_back(provider: Option<&Provider>) -> (u64, u64) {
    provider.map_or((0, 0), |p| (p.ledger.given_back(), p.ledger.gone_held()))
}

#[cfg(not(feature = "shared-memory"))]
fn given_back(_: Option<&Provider>) -> (u64, u64) {
    (0, 0)
}

/// Gives back what gone readers held (reclaim.rs); whether anything came back, so
/// that an allocation that failed is worth trying again.
#[cfg(feature = "shared-memory")]
fn retry(provider: &Provider) -> bool {
    provider.reclaim() > 0
}

#[cfg(not(feature = "shared-memory"))]
fn retry(provider: &Provider) -> bool {
    match *provider {}
}

/// The bytes `provider` has free once the buffers nobody holds are collected.
#[cfg(feature = "shared-memory")]
fn free_after_collecting(provider: &Provider) -> usize {
    provider.zenoh.garbage_collect();
    provider.zenoh.available()
}

#[cfg(not(feature = "shared-memory"))]
fn free_after_collecting(provider: &Provider) -> usize {
    match *provider {}
}

/// How many buffers of `size` bytes `provider` hands out, all held at once.
#[cfg(feature = "shared-memory")]
fn buffers_of(provider: &Provider, size: usize) -> usize {
    let mut held = Vec::new();
    let alloc = || {
        (provider.zenoh.alloc(size.max(1)))
            .with_policy::<Reclaim>()
            .wait()
    };
    while let Ok(buffer) = alloc() {
        held.push(buffer);
    }
    held.len()
}

#[cfg(not(feature = "shared-memory"))]
fn buffers_of(provider: &Provider, _: usize) -> usize {
    match *provider {}
}

#[cfg(all(test, feature = "shared-memory"))]
mod tests;
