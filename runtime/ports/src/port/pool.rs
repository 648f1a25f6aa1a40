//! Buffer pools: where the values of an output port live.
//!
//! A pool owns *slots*. A slot is one heap allocation holding a reference count, a
//! free-list link, the pool it belongs to and the value itself. Slots are created on
//! demand (only when every existing one is in use) and are **never freed while the pool
//! has a handle**; a slot whose last reference is dropped goes back on the pool's free
//! list and keeps its value, so the next publisher can overwrite it in place (a `Vec`
//! keeps its capacity, an image buffer its memory: no allocation in steady state).
//!
//! # Invariants
//!
//! * **Slot state.** `refs == 0` means the slot is free (on the free list) or owned
//!   exclusively by a writer (a [`BufferMut`](super::BufferMut)). `refs > 0` means it is
//!   published and its value is immutable until `refs` returns to 0. A reader may only
//!   increment `refs` from a non-zero value (see [`try_retain`]), so it can never obtain
//!   a slot that a writer is filling.
//! * **Type-stable memory.** While the pool has at least one [`PoolHandle`], no slot is
//!   deallocated: a reader holding a possibly stale slot pointer may always touch the
//!   slot's `refs` word. Whoever may read stale pointers (a value cell) keeps a handle
//!   of every pool whose slots can reach it.
//! * **Lifetime.** Each slot holds an `Arc` of its pool's [`Shared`] (cloned once, when
//!   the slot is created), so the free list outlives every live slot. When the last
//!   handle is dropped the pool is *orphaned*: the free slots are freed at once and the
//!   orphan bit in the free-list head makes every slot released later free itself
//!   instead of going back on the list. The orphan bit and the free-list link change in
//!   the same atomic word, so a slot is either on the list when the list is taken, or
//!   sees the bit — never neither.
//! * **Free list.** A Treiber stack of slot indices. Its head packs the index (32 bits),
//!   an ABA tag bumped by every successful change (31 bits) and the orphan bit. Popping
//!   reads `next` of a slot that another thread may have popped meanwhile; that is safe
//!   (memory is type-stable, `next` is atomic) and the tag makes the stale CAS fail. A
//!   false success would need 2^31 list operations during one preempted pop.

use std::cell::UnsafeCell;
use std::ptr::{self, NonNull};

use crate::sync::{fence, lock, Arc, AtomicPtr, AtomicU64, AtomicUsize, Mutex, Ordering};

/// More references than this on one slot means a reference leak in a loop; like
/// `Arc`, abort instead of risking an overflow of the count.
const MAX_REFS: usize = usize::MAX / 2;

const IDX_MASK: u64 = 0xFFFF_FFFF;
const ORPHAN: u64 = 1 << 63;
const TAG_ONE: u64 = 1 << 32;
const TAG_MASK: u64 = !IDX_MASK & !ORPHAN;

/// Segment `k` of the slot table holds `2^k` entries; 31 segments give 2^31 - 1 slots,
/// so an index plus one always fits the 32 index bits of the free-list head.
const SEGMENTS: usize = 31;

/// One buffer: the reference count, the free-list link and the value.
pub(crate) struct Slot<T> {
    /// Number of holders (port references, value cells, queue entries).
    refs: AtomicUsize,
    /// Index + 1 of the next free slot while on the free list; 0 ends the list.
    next: AtomicUsize,
    index: usize,
    pool: Arc<Shared<T>>,
    value: UnsafeCell<T>,
}

impl<T> Slot<T> {
    /// Pointer to the value. Reading it requires a reference (`refs > 0`); writing it
    /// requires exclusive ownership (`refs == 0` and the slot off the free list).
    pub(crate) fn value_ptr(slot: NonNull<Self>) -> *mut T {
        // SAFETY: `slot` points to a live slot (caller's contract); UnsafeCell::get only
        // computes the address.
        unsafe { (*slot.as_ptr()).value.get() }
    }

    /// Sets the reference count of a slot the caller owns exclusively (about to be
    /// published). Release: the value written before becomes visible to every holder.
    ///
    /// # Safety
    /// The caller owns the slot exclusively (`refs == 0`, not on the free list).
    pub(crate) unsafe fn set_refs(slot: NonNull<Self>, n: usize) {
        // SAFETY: live slot (caller's contract).
        unsafe { (*slot.as_ptr()).refs.store(n, Ordering::Release) }
    }

    /// Adds `n` references. The caller already holds one, so the slot is live.
    ///
    /// # Safety
    /// The caller holds at least one reference.
    pub(crate) unsafe fn add_refs(slot: NonNull<Self>, n: usize) {
        // SAFETY: the caller's reference keeps the slot live.
        let old = unsafe { (*slot.as_ptr()).refs.fetch_add(n, Ordering::Relaxed) };
        if old > MAX_REFS {
            std::process::abort();
        }
    }
}

/// Tries to take one more reference on a slot reached through a possibly stale pointer.
/// Succeeds only while the slot is published (`refs > 0`), so a slot being recycled or
/// refilled is never handed out.
///
/// # Safety
/// `slot` must point to slot memory that is still allocated (type-stable pool memory:
/// the caller keeps a handle of the slot's pool).
pub(crate) unsafe fn try_retain<T>(slot: NonNull<Slot<T>>) -> bool {
    // SAFETY: allocated slot memory (caller's contract); only the atomic is touched.
    let refs = unsafe { &(*slot.as_ptr()).refs };
    let mut cur = refs.load(Ordering::Relaxed);
    loop {
        if cur == 0 {
            return false;
        }
        if cur > MAX_REFS {
            std::process::abort();
        }
        // Acquire: pairs with the publisher's Release in `set_refs` (and the release
        // sequence of increments after it), so the value is visible once we hold it.
        match refs.compare_exchange_weak(cur, cur + 1, Ordering::Acquire, Ordering::Relaxed) {
            Ok(_) => return true,
            Err(actual) => cur = actual,
        }
    }
}

/// Drops `n` references held by the caller; the last one recycles the slot.
///
/// # Safety
/// The caller owns `n` references of a live slot and gives them up.
pub(crate) unsafe fn release<T>(slot: NonNull<Slot<T>>, n: usize) {
    // SAFETY: the caller's references keep the slot live until this decrement.
    let prev = unsafe { (*slot.as_ptr()).refs.fetch_sub(n, Ordering::Release) };
    debug_assert!(prev >= n, "slot reference count underflow");
    if prev == n {
        // Every other holder's reads happen before our reuse (same pattern as Arc).
        fence(Ordering::Acquire);
        // SAFETY: the count reached 0: we are the only owner of the slot now.
        unsafe { recycle(slot) }
    }
}

/// Puts an exclusively owned slot back on its pool's free list, or frees it if the pool
/// is orphaned.
///
/// Takes raw pointers on purpose: freeing the slot may drop the last `Arc` of the pool,
/// so no reference to the pool may outlive that point (not even a `&self` argument).
///
/// # Safety
/// The caller owns the slot exclusively (`refs == 0`, not on the free list).
pub(crate) unsafe fn recycle<T>(slot: NonNull<Slot<T>>) {
    let sp = slot.as_ptr();
    // SAFETY: the slot is live and its `pool` field keeps `Shared` alive until the slot
    // itself is freed below.
    let shared: *const Shared<T> = unsafe { Arc::as_ptr(&(*sp).pool) };
    // SAFETY: as above.
    let idx1 = unsafe { (*sp).index } as u64 + 1;
    // SAFETY: `shared` is alive (see above); the temporary reference ends with the load.
    let mut head = unsafe { (*shared).head.load(Ordering::Relaxed) };
    loop {
        if head & ORPHAN != 0 {
            // SAFETY: exclusive owner of a slot that came from `Box::into_raw`; the pool
            // is orphaned so nobody else will look it up. `shared` is not used after.
            drop(unsafe { Box::from_raw(sp) });
            return;
        }
        // SAFETY: exclusive owner; `next` is only meaningful once the CAS publishes it.
        unsafe {
            (*sp)
                .next
                .store((head & IDX_MASK) as usize, Ordering::Relaxed)
        };
        // Release: our use of the slot (and the `next` store) happens before the next pop.
        // SAFETY: `shared` is alive (held by this slot).
        match unsafe { &(*shared).head }.compare_exchange_weak(
            head,
            bump(head, idx1),
            Ordering::Release,
            Ordering::Relaxed,
        ) {
            Ok(_) => return,
            Err(actual) => head = actual,
        }
    }
}

fn bump(head: u64, idx1: u64) -> u64 {
    ((head & TAG_MASK).wrapping_add(TAG_ONE) & TAG_MASK) | (head & ORPHAN) | idx1
}

type Init<T> = Box<dyn Fn() -> T + Send + Sync>;

/// The part of a pool that slots point back to.
pub(crate) struct Shared<T> {
    /// Free-list head: index + 1 (0 = empty) | ABA tag | orphan bit.
    head: AtomicU64,
    /// Number of [`PoolHandle`]s.
    handles: AtomicUsize,
    /// Number of slots ever created (for statistics and the next index).
    created: AtomicUsize,
    /// Index → slot, append-only; never read after the pool is orphaned.
    segments: [AtomicPtr<AtomicPtr<Slot<T>>>; SEGMENTS],
    /// Serialises growth; holds the factory for new values (none for input defaults).
    grow: Mutex<Option<Init<T>>>,
}

fn locate(index: usize) -> (usize, usize) {
    let n = index + 1;
    let k = (usize::BITS - 1 - n.leading_zeros()) as usize;
    (k, n - (1usize << k))
}

impl<T> Shared<T> {
    /// The slot with this index. Only valid for created indices of a pool that is not
    /// orphaned.
    fn slot(&self, index: usize) -> NonNull<Slot<T>> {
        let (k, off) = locate(index);
        let seg = self.segments[k].load(Ordering::Acquire);
        debug_assert!(!seg.is_null());
        // SAFETY: segment `k` exists for every created index and has 2^k entries.
        let entry = unsafe { &*seg.add(off) };
        let p = entry.load(Ordering::Acquire);
        NonNull::new(p).unwrap_or_else(|| unreachable!("free-list index without a slot"))
    }
}

impl<T> Drop for Shared<T> {
    fn drop(&mut self) {
        // Only the table is owned here: every slot was freed before its Arc let go.
        for (k, seg) in self.segments.iter().enumerate() {
            let p = seg.load(Ordering::Relaxed);
            if !p.is_null() {
                // SAFETY: allocated in `PoolHandle::insert` as a boxed slice of 2^k.
                drop(unsafe { Box::from_raw(ptr::slice_from_raw_parts_mut(p, 1usize << k)) });
            }
        }
    }
}

/// Counted ownership of a pool: while one exists, no slot of the pool is freed.
pub(crate) struct PoolHandle<T> {
    shared: Arc<Shared<T>>,
}

/// Statistics of one pool.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PoolStats {
    /// Buffers created so far (the pool never shrinks while the port lives).
    pub buffers: usize,
}

impl<T: Send + Sync + 'static> PoolHandle<T> {
    fn empty(init: Option<Init<T>>) -> Self {
        let shared = Shared {
            head: AtomicU64::new(0),
            handles: AtomicUsize::new(1),
            created: AtomicUsize::new(0),
            segments: std::array::from_fn(|_| AtomicPtr::new(ptr::null_mut())),
            grow: Mutex::new(init),
        };
        PoolHandle {
            shared: Arc::new(shared),
        }
    }

    /// A growable pool whose new buffers start as `init()`.
    pub(crate) fn new(init: Init<T>) -> Self {
        Self::empty(Some(init))
    }

    /// A pool of exactly one buffer holding `value`, returned already owned (refs 0,
    /// off the free list) so the caller can publish it. Used for default values.
    pub(crate) fn single(value: T) -> (Self, NonNull<Slot<T>>) {
        let pool = Self::empty(None);
        let slot = pool.insert(value);
        (pool, slot)
    }

    /// Takes a free buffer for writing, creating one if all are in use.
    pub(crate) fn acquire(&self) -> NonNull<Slot<T>> {
        match self.pop() {
            Some(slot) => slot,
            None => self.grow_one(),
        }
    }

    /// Makes sure at least `n` buffers exist (so later publishes need not allocate).
    pub(crate) fn reserve(&self, n: usize) {
        while self.shared.created.load(Ordering::Acquire) < n {
            let slot = self.grow_one();
            // SAFETY: freshly created, owned exclusively.
            unsafe { recycle(slot) };
        }
    }

    pub(crate) fn stats(&self) -> PoolStats {
        PoolStats {
            buffers: self.shared.created.load(Ordering::Acquire),
        }
    }

    /// Same pool?
    pub(crate) fn same_pool(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.shared, &other.shared)
    }

    fn pop(&self) -> Option<NonNull<Slot<T>>> {
        let shared = &*self.shared;
        let mut head = shared.head.load(Ordering::Acquire);
        loop {
            debug_assert!(head & ORPHAN == 0, "pop from an orphaned pool");
            let idx1 = head & IDX_MASK;
            if idx1 == 0 {
                return None;
            }
            let slot = shared.slot((idx1 - 1) as usize);
            // SAFETY: type-stable memory (we hold a handle). The slot may have been popped
            // by someone else meanwhile; then `next` is stale and the tag fails the CAS.
            let next = unsafe { (*slot.as_ptr()).next.load(Ordering::Relaxed) } as u64;
            // Acquire: pairs with the Release of the push that put the slot here.
            match shared.head.compare_exchange_weak(
                head,
                bump(head, next),
                Ordering::Acquire,
                Ordering::Acquire,
            ) {
                Ok(_) => return Some(slot),
                Err(actual) => head = actual,
            }
        }
    }

    fn grow_one(&self) -> NonNull<Slot<T>> {
        // Run the user's factory outside the lock, then register under it.
        let value = {
            let init = lock(&self.shared.grow);
            match init.as_ref() {
                Some(f) => f(),
                None => unreachable!("a single-value pool never grows"),
            }
        };
        self.insert(value)
    }

    fn insert(&self, value: T) -> NonNull<Slot<T>> {
        let _serial = lock(&self.shared.grow);
        let index = self.shared.created.load(Ordering::Relaxed);
        assert!(
            index < (1usize << SEGMENTS) - 1,
            "port buffer pool exhausted: {index} buffers are held at once"
        );
        let slot = Box::into_raw(Box::new(Slot {
            refs: AtomicUsize::new(0),
            next: AtomicUsize::new(0),
            index,
            pool: Arc::clone(&self.shared),
            value: UnsafeCell::new(value),
        }));
        let (k, off) = locate(index);
        let mut seg = self.shared.segments[k].load(Ordering::Acquire);
        if seg.is_null() {
            let entries: Box<[AtomicPtr<Slot<T>>]> = (0..1usize << k)
                .map(|_| AtomicPtr::new(ptr::null_mut()))
                .collect();
            seg = Box::into_raw(entries).cast::<AtomicPtr<Slot<T>>>();
            self.shared.segments[k].store(seg, Ordering::Release);
        }
        // SAFETY: segment k has 2^k entries and `off < 2^k`.
        unsafe { &*seg.add(off) }.store(slot, Ordering::Release);
        self.shared.created.store(index + 1, Ordering::Release);
        // SAFETY: Box::into_raw never returns null.
        unsafe { NonNull::new_unchecked(slot) }
    }
}

impl<T> Clone for PoolHandle<T> {
    fn clone(&self) -> Self {
        self.shared.handles.fetch_add(1, Ordering::Relaxed);
        PoolHandle {
            shared: Arc::clone(&self.shared),
        }
    }
}

impl<T> Drop for PoolHandle<T> {
    fn drop(&mut self) {
        if self.shared.handles.fetch_sub(1, Ordering::AcqRel) != 1 {
            return;
        }
        // Last handle: orphan the pool and free every slot on the free list. Our own Arc
        // keeps `Shared` alive during this.
        let shared = &*self.shared;
        let mut head = shared.head.load(Ordering::Acquire);
        loop {
            let orphaned = ((head & TAG_MASK).wrapping_add(TAG_ONE) & TAG_MASK) | ORPHAN;
            match shared.head.compare_exchange_weak(
                head,
                orphaned,
                Ordering::AcqRel,
                Ordering::Acquire,
            ) {
                Ok(_) => break,
                Err(actual) => head = actual,
            }
        }
        let mut idx1 = (head & IDX_MASK) as usize;
        while idx1 != 0 {
            let slot = shared.slot(idx1 - 1);
            // SAFETY: the taken list is ours alone: no handle means no pops, and pushes
            // after the orphan bit free their slot instead.
            idx1 = unsafe { (*slot.as_ptr()).next.load(Ordering::Relaxed) };
            // SAFETY: slot came from Box::into_raw and is owned exclusively (see above).
            drop(unsafe { Box::from_raw(slot.as_ptr()) });
        }
    }
}
