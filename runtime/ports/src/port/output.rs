//! [`OutputPort`]: publishes buffers from its own pool, zero-copy.

use std::fmt;
use std::ptr::NonNull;

use super::cell::ValueCell;
use super::input::InputCore;
use super::pool::{self, PoolHandle, PoolStats, Slot};
use super::wiring::{self, Fanout, OutCore};
use super::{BufferMut, PortRef};
use crate::sync::{Arc, Ordering};

pub(crate) struct OutputCore<T: Send + Sync + 'static> {
    name: String,
    /// The last published value (or the initial value). Declared before the pools so it
    /// is released first on drop.
    pub(crate) cell: ValueCell<T>,
    pool: PoolHandle<T>,
    /// The initial value lives in a pool of its own that never hands out buffers, so
    /// "the cell still holds the initial slot" means "never published".
    initial: usize,
    /// Owns the initial value's slot (never read, only kept).
    _initial_pool: PoolHandle<T>,
    fanout: Fanout<InputCore<T>>,
}

/// An output data port for values of any `T: Send + Sync + 'static`.
///
/// The port owns a pool of buffers. [`publish`](Self::publish),
/// [`publish_with`](Self::publish_with) or [`acquire`](Self::acquire) +
/// [`BufferMut::publish`] fill an unused buffer and make it the port's value with one
/// atomic swap; every connected input then receives a reference to the same buffer
/// (no copy). Buffers return to the pool when the last reader drops its [`PortRef`].
/// In steady state publishing neither locks nor allocates; the pool grows only when
/// every buffer is held (by readers, inputs, queues) at the moment of a publish.
///
/// Publishing takes `&self`, so several threads may publish on one port; such
/// concurrent publishes are not ordered with each other, and different inputs may end
/// up holding different ones of them (each input: the last delivery wins).
///
/// # Panics
/// Publishing panics if more than 2^31 - 2 buffers of one port are held at once.
pub struct OutputPort<T: Send + Sync + 'static> {
    pub(crate) core: Arc<OutputCore<T>>,
}

impl<T: Send + Sync + 'static> OutputPort<T> {
    /// A port whose initial value and new buffers are `T::default()`.
    pub fn new(name: impl Into<String>) -> Self
    where
        T: Default,
    {
        Self::with_init(name, T::default)
    }

    /// A port whose initial value and new buffers are made by `init` (called again
    /// only when the pool has to grow).
    pub fn with_init(
        name: impl Into<String>,
        init: impl Fn() -> T + Send + Sync + 'static,
    ) -> Self {
        let (initial_pool, initial) = PoolHandle::single(init());
        // SAFETY: the fresh slot is ours alone; the cell takes its only reference.
        unsafe { Slot::set_refs(initial, 1) };
        // SAFETY: one reference, owned, moved into the cell.
        let cell = ValueCell::new(unsafe { PortRef::from_raw(initial) });
        let core = OutputCore {
            name: name.into(),
            cell,
            pool: PoolHandle::new(Box::new(init)),
            initial: initial.as_ptr().addr(),
            _initial_pool: initial_pool,
            fanout: Fanout::new(),
        };
        OutputPort {
            core: Arc::new(core),
        }
    }

    /// The port's name.
    pub fn name(&self) -> &str {
        &self.core.name
    }

    /// Takes an unused buffer to fill in place. It holds whatever value it had when it
    /// was last used (reuse keeps its allocations), so overwrite what you need.
    pub fn acquire(&self) -> BufferMut<'_, T> {
        BufferMut {
            slot: self.core.pool.acquire(),
            port: &self.core,
        }
    }

    /// Publishes `value` (moved into a pooled buffer; the buffer's old value is dropped
    /// once the inputs have the new one: an input's notifier may run its reader's cycle
    /// right there (`wait="inline"`), which the old value's drop — a received buffer
    /// given back, its bookkeeping — would only delay).
    pub fn publish(&self, mut value: T) {
        let mut buf = self.acquire();
        // Swapped, not moved out: no second copy of a large `T` on the stack.
        std::mem::swap(&mut *buf, &mut value);
        buf.publish();
        drop(value);
    }

    /// Fills a pooled buffer in place with `fill` and publishes it.
    pub fn publish_with(&self, fill: impl FnOnce(&mut T)) {
        let mut buf = self.acquire();
        fill(&mut buf);
        buf.publish();
    }

    /// The port's current value: the last one published, or the initial value.
    pub fn get(&self) -> PortRef<T> {
        self.core.cell.get()
    }

    /// Number of connected inputs.
    pub fn connection_count(&self) -> usize {
        self.core.fanout.len()
    }

    /// Pool statistics (buffers created so far).
    pub fn stats(&self) -> PoolStats {
        self.core.pool.stats()
    }

    /// Creates buffers until the pool has at least `n`, so that later publishes with up
    /// to that many buffers held at once never allocate.
    pub fn reserve(&self, n: usize) {
        self.core.pool.reserve(n);
    }

    /// Disconnects every input.
    pub fn disconnect_all(&self) {
        wiring::disconnect_all_targets(&self.core);
    }
}

impl<T: Send + Sync + 'static> Drop for OutputPort<T> {
    fn drop(&mut self) {
        self.disconnect_all();
    }
}

impl<T: Send + Sync + 'static> fmt::Debug for OutputPort<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("OutputPort")
            .field("name", &self.core.name)
            .field("connections", &self.connection_count())
            .finish()
    }
}

/// Deliveries to `block` queues that were full, finished after the list is released.
pub(crate) type Deferred<T> = Vec<(Arc<InputCore<T>>, PortRef<T>)>;

impl<T: Send + Sync + 'static> OutputCore<T> {
    /// Publishes an exclusively owned slot.
    ///
    /// 1. Set the slot's count to 1 (our cell) + the references the inputs will take,
    ///    guessed from `refs_hint`, plus one we hold while delivering if there are none.
    /// 2. Swap it into our cell (SeqCst): it is now the port's value.
    /// 3. Load the input list (SeqCst, after the swap: see `wiring::connect`), correct
    ///    the count if the list changed since the guess, and hand each input its
    ///    references.
    pub(crate) fn publish_slot(&self, slot: NonNull<Slot<T>>) {
        let guess = self.fanout.refs_hint.load(Ordering::Relaxed);
        let held = guess.max(1);
        // SAFETY: the slot is ours alone until published.
        unsafe { Slot::set_refs(slot, 1 + held) };
        // SAFETY: our own pool is retained by this core as long as the cell exists.
        unsafe { self.cell.store(PortRef::from_raw(slot), false) };
        let reader = self.fanout.snap.read();
        let targets = reader.load();
        if targets.refs > held {
            // SAFETY: we still hold `held >= 1` references.
            unsafe { Slot::add_refs(slot, targets.refs - held) };
        } else if targets.refs < held {
            // SAFETY: we give up the references no input will take.
            unsafe { pool::release(slot, held - targets.refs) };
        }
        let mut deferred: Deferred<T> = Vec::new();
        for input in &targets.list {
            InputCore::deliver(input, slot, &mut deferred);
        }
        drop(reader);
        for (input, value) in deferred {
            input.deliver_blocking(self, value);
        }
    }
}

impl<T: Send + Sync + 'static> OutCore for OutputCore<T> {
    type In = InputCore<T>;

    fn name(&self) -> &str {
        &self.name
    }

    fn fanout(&self) -> &Fanout<InputCore<T>> {
        &self.fanout
    }

    fn retain(&self, retained: &mut Vec<PoolHandle<T>>) {
        if !retained.iter().any(|p| p.same_pool(&self.pool)) {
            retained.push(self.pool.clone());
        }
    }

    fn initial_push(&self, input: &InputCore<T>, mark: (usize, PortRef<T>)) {
        let value = self.cell.get();
        let slot = value.into_raw();
        if slot.as_ptr().addr() == self.initial {
            // SAFETY: the reference from `get` is ours.
            unsafe { pool::release(slot, 1) };
            return;
        }
        // SAFETY: reference from `get`, moved on.
        input.initial_value(unsafe { PortRef::from_raw(slot) }, mark);
    }
}
