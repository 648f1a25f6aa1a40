//! [`InputPort`]: receives references to buffers published by connected outputs.

use std::fmt;
use std::ptr::NonNull;
use std::time::{Duration, Instant};

use super::cell::ValueCell;
use super::notify::{Notifier, SetOnce};
use super::output::{Deferred, OutputCore};
use super::pool::{PoolHandle, Slot};
use super::queue::{OnFull, Queue, QueueConfig, Signal};
use super::wiring::{self, InCore, InputSources};
use super::PortRef;
use crate::sync::{Arc, Mutex};

pub(crate) struct InputCore<T: Send + Sync + 'static> {
    name: String,
    /// Latest value (also for queued inputs). Declared before `input_sources` so it is released
    /// before the retained pools on drop.
    cell: ValueCell<T>,
    queue: Option<Queue<PortRef<T>>>,
    signal: Signal,
    notifier: SetOnce<Notifier>,
    /// Sources, and a handle of every pool whose buffers may reach `cell` (our own
    /// default's pool and each output's ever connected): the cell's safety contract.
    input_sources: Mutex<InputSources<OutputCore<T>, Vec<PoolHandle<T>>>>,
}

/// An input data port.
///
/// By default it has latest-value semantics: [`get`](Self::get) returns the value most
/// recently delivered by any connected output (last writer wins), or the port's default
/// value before anything arrived. Created with [`queued`](Self::queued), it also keeps
/// a bounded FIFO of every delivered value, read with [`try_pop`](Self::try_pop),
/// [`pop`](Self::pop) and [`pop_timeout`](Self::pop_timeout).
///
/// Memory: an input keeps the buffer pool of every output it has ever been connected
/// to (once per output) until the input is dropped, even after disconnecting. That is
/// what lets [`get`](Self::get) read without locks while connections change: a buffer
/// it is about to reference may be recycled, but never freed. Wiring that keeps
/// creating new outputs for one long-lived input therefore grows that input's memory.
pub struct InputPort<T: Send + Sync + 'static> {
    pub(crate) core: Arc<InputCore<T>>,
}

impl<T: Send + Sync + 'static> InputPort<T> {
    /// A latest-value input whose default value is `T::default()`.
    pub fn new(name: impl Into<String>) -> Self
    where
        T: Default,
    {
        Self::build(name.into(), T::default(), None)
    }

    /// A latest-value input with the given default value.
    pub fn with_default(name: impl Into<String>, value: T) -> Self {
        Self::build(name.into(), value, None)
    }

    /// A queued input (`queue=N`, `on-full=…`) whose default value is `T::default()`.
    pub fn queued(name: impl Into<String>, queue: QueueConfig) -> Self
    where
        T: Default,
    {
        Self::build(name.into(), T::default(), Some(queue))
    }

    /// A queued input with the given default value (what `get` returns before the first
    /// delivery).
    pub fn queued_with_default(name: impl Into<String>, queue: QueueConfig, value: T) -> Self {
        Self::build(name.into(), value, Some(queue))
    }

    fn build(name: String, value: T, queue: Option<QueueConfig>) -> Self {
        let (pool, slot) = PoolHandle::single(value);
        // SAFETY: the fresh slot is ours alone; the cell takes its only reference.
        unsafe { Slot::set_refs(slot, 1) };
        // SAFETY: one owned reference moved into the cell.
        let cell = ValueCell::new(unsafe { PortRef::from_raw(slot) });
        let core = InputCore {
            name,
            cell,
            queue: queue.map(Queue::new),
            signal: Signal::new(),
            notifier: SetOnce::new(),
            input_sources: Mutex::new(InputSources {
                sources: Vec::new(),
                retained: vec![pool],
            }),
        };
        InputPort {
            core: Arc::new(core),
        }
    }

    /// The port's name.
    pub fn name(&self) -> &str {
        &self.core.name
    }

    /// The latest value delivered (or the default). Lock-free, zero-copy.
    pub fn get(&self) -> PortRef<T> {
        self.core.cell.get()
    }

    /// Has a value been delivered since the last [`take_changed`](Self::take_changed)
    /// (or [`pop`](Self::pop) of a latest-value input)?
    pub fn has_changed(&self) -> bool {
        self.core.cell.has_changed()
    }

    /// Clears the changed mark and returns whether it was set. Call it before
    /// [`get`](Self::get): a delivery after it sets the mark again.
    pub fn take_changed(&self) -> bool {
        self.core.cell.take_changed()
    }

    /// The queue settings, if this is a queued input.
    pub fn queue_config(&self) -> Option<QueueConfig> {
        self.core.queue.as_ref().map(Queue::config)
    }

    /// Number of values waiting in the queue (0 for a latest-value input).
    pub fn queued_len(&self) -> usize {
        self.core.queue.as_ref().map_or(0, Queue::len)
    }

    /// Takes the next value not taken yet, without waiting: the oldest queued value,
    /// or — for a latest-value input — the current value if it changed since it was
    /// last taken.
    pub fn try_pop(&self) -> Option<PortRef<T>> {
        match &self.core.queue {
            Some(q) => {
                let v = q.pop()?;
                if q.config().on_full == OnFull::Block {
                    self.core.signal.notify_space();
                }
                Some(v)
            }
            None => self.take_changed().then(|| self.get()),
        }
    }

    /// Like [`try_pop`](Self::try_pop), but waits for a value.
    pub fn pop(&self) -> PortRef<T> {
        loop {
            if let Some(v) = self.pop_until(None) {
                return v;
            }
        }
    }

    /// Like [`pop`](Self::pop) with a time limit; `None` on timeout.
    pub fn pop_timeout(&self, timeout: Duration) -> Option<PortRef<T>> {
        self.pop_until(Some(Instant::now() + timeout))
    }

    fn pop_until(&self, deadline: Option<Instant>) -> Option<PortRef<T>> {
        loop {
            if let Some(v) = self.try_pop() {
                return Some(v);
            }
            let cell = &self.core.cell;
            let ready: Box<dyn FnMut() -> bool + '_> = match &self.core.queue {
                // Holding the current value keeps its version from coming back (ABA).
                Some(q) => {
                    let (version, seen) = cell.mark();
                    Box::new(move || {
                        let _keep = &seen;
                        q.len() != 0 || cell.version() != version
                    })
                }
                None => Box::new(|| cell.has_changed()),
            };
            if !self.core.signal.wait_data(ready, deadline) {
                return None;
            }
        }
    }

    /// Registers the notifier every delivery to this input calls (once per input; a
    /// thread container registers its wakeup). Gives it back if one is already set.
    pub fn set_notifier(&self, notifier: Notifier) -> Result<(), Notifier> {
        self.core.notifier.set(notifier)
    }

    /// Number of connected outputs.
    pub fn connection_count(&self) -> usize {
        crate::sync::lock(&self.core.input_sources).sources.len()
    }

    /// Disconnects every output.
    pub fn disconnect_all(&self) {
        wiring::disconnect_all_sources(&self.core);
    }
}

impl<T: Send + Sync + 'static> Drop for InputPort<T> {
    fn drop(&mut self) {
        self.disconnect_all();
    }
}

impl<T: Send + Sync + 'static> fmt::Debug for InputPort<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("InputPort")
            .field("name", &self.core.name)
            .field("queue", &self.queue_config())
            .finish()
    }
}

impl<T: Send + Sync + 'static> InputCore<T> {
    /// Hands this input its references of a slot being published (1, or 2 when queued:
    /// queue + latest value). A full `block` queue defers its part to `deferred`.
    pub(crate) fn deliver(this: &Arc<Self>, slot: NonNull<Slot<T>>, deferred: &mut Deferred<T>) {
        if let Some(q) = &this.queue {
            // SAFETY: the publisher set aside one reference for our queue.
            let queued = unsafe { PortRef::from_raw(slot) };
            if let Err(back) = q.offer(queued) {
                deferred.push((Arc::clone(this), back));
            }
        }
        // SAFETY: we retain the publisher's pool (added at connect, before it could
        // reach us, kept until we are dropped); one reference set aside for our cell.
        unsafe { this.cell.store(PortRef::from_raw(slot), true) };
        this.delivered();
    }

    /// Waits for room in the `block` queue, unless `out` is disconnected meanwhile.
    pub(crate) fn deliver_blocking(&self, out: &OutputCore<T>, value: PortRef<T>) {
        let Some(q) = &self.queue else { return };
        let mut pending = Some(value);
        self.signal.wait_space(|| {
            let Some(v) = pending.take() else { return true };
            match q.push(v) {
                Ok(()) => true,
                Err(back) => {
                    pending = Some(back);
                    !wiring::is_source(self, out)
                }
            }
        });
        if pending.is_none() {
            self.delivered();
        }
    }

    /// Initial push at connect time, if nothing arrived since `mark`.
    pub(crate) fn initial_value(&self, value: PortRef<T>, mark: (usize, PortRef<T>)) {
        // SAFETY: the output's pool was retained at connect.
        if unsafe { self.cell.replace_if(mark.0, value) } {
            self.delivered();
        }
    }

    fn delivered(&self) {
        self.signal.notify_data();
        if let Some(n) = self.notifier.get() {
            n.notify();
        }
    }
}

impl<T: Send + Sync + 'static> InCore for InputCore<T> {
    type Out = OutputCore<T>;
    type Retained = Vec<PoolHandle<T>>;
    /// The cell version, and a reference that keeps that version from recurring.
    type Mark = (usize, PortRef<T>);

    fn name(&self) -> &str {
        &self.name
    }

    fn input_sources(&self) -> &Mutex<InputSources<OutputCore<T>, Vec<PoolHandle<T>>>> {
        &self.input_sources
    }

    fn refs_per_delivery(&self) -> usize {
        1 + usize::from(self.queue.is_some())
    }

    fn is_queued(&self) -> bool {
        self.queue.is_some()
    }

    fn mark(&self) -> Self::Mark {
        self.cell.mark()
    }

    fn wake_producers(&self) {
        self.signal.notify_space();
    }
}

impl<T: Send + Sync + 'static> super::handle::HasNotifier for InputCore<T> {
    fn set_notifier(&self, notifier: Notifier) -> Result<(), Notifier> {
        self.notifier.set(notifier)
    }
}
