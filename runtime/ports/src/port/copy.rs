//! [`CopyOutputPort`] / [`CopyInputPort`]: the cheap path for small `Copy` values.
//!
//! Same connections, queues and wakeups as the buffer ports, but values are copied
//! into each port's [`SeqCell`] instead of shared through a reference-counted buffer:
//! for a few machine words a copy is cheaper than counting references, and `get`
//! returns `T` by value.

use std::fmt;
use std::time::{Duration, Instant};

use bytemuck::NoUninit;

use super::copy_local::{LocalIn, LocalOut};
use super::notify::{Notifier, SetOnce};
use super::queue::{OnFull, Queue, QueueConfig, Signal};
use super::seqlock::SeqCell;
use super::wiring::{self, Fanout, InCore, InputSources, OutCore};
use crate::sync::{lock, Arc, Mutex};

pub(crate) struct CopyOutputCore<T: NoUninit + Send + Sync> {
    pub(crate) name: String,
    /// The shared value (lock-free path).
    pub(crate) cell: SeqCell<T>,
    pub(crate) fanout: Fanout<CopyInputCore<T>>,
    /// The value for readers in the same thread container (`copy_local.rs`).
    pub(crate) local: LocalOut<T>,
}

pub(crate) struct CopyInputCore<T: NoUninit + Send + Sync> {
    pub(crate) name: String,
    pub(crate) cell: SeqCell<T>,
    pub(crate) queue: Option<Queue<T>>,
    signal: Signal,
    notifier: SetOnce<Notifier>,
    pub(crate) input_sources: Mutex<InputSources<CopyOutputCore<T>, ()>>,
    /// Set while the input reads its output's local cell (`copy_local.rs`).
    pub(crate) local: LocalIn<T>,
}

/// An output port for small, padding-free `Copy` values ([`NoUninit`]; derive it with
/// `#[derive(Clone, Copy, bytemuck::NoUninit)]` and `#[repr(C)]`).
///
/// Publishing copies the value into the port and into every connected input (a
/// seqlock write each: no locks, no allocation, no reference counting). Connections
/// the Builder made local to one thread container (`port/local.rs`) skip all of that:
/// the value is stored once in a plain cell that their inputs read.
///
/// # Panics
/// Using the port from another thread than its container's while it has local
/// connections panics (a module's ports belong to the thread that runs it).
pub struct CopyOutputPort<T: NoUninit + Send + Sync> {
    pub(crate) core: Arc<CopyOutputCore<T>>,
}

/// Reads a copy input's latest value without taking its changed mark (and without
/// owning the port: dropping it does not disconnect anything).
#[doc(hidden)]
pub struct CopyPeek<T: NoUninit + Send + Sync>(Arc<CopyInputCore<T>>);

impl<T: NoUninit + Send + Sync> CopyPeek<T> {
    /// The latest value delivered to the input.
    #[doc(hidden)]
    pub fn get(&self) -> T {
        self.0.read()
    }
}

/// An input port for [`CopyOutputPort`]s: latest value by default, or a queue.
pub struct CopyInputPort<T: NoUninit + Send + Sync> {
    pub(crate) core: Arc<CopyInputCore<T>>,
}

impl<T: NoUninit + Send + Sync> CopyOutputPort<T> {
    /// A port whose initial value is `T::default()`.
    pub fn new(name: impl Into<String>) -> Self
    where
        T: Default,
    {
        Self::with_value(name, T::default())
    }

    /// A port with the given initial value.
    pub fn with_value(name: impl Into<String>, value: T) -> Self {
        let core = CopyOutputCore {
            name: name.into(),
            cell: SeqCell::new(value),
            fanout: Fanout::new(),
            local: LocalOut::new(value),
        };
        CopyOutputPort {
            core: Arc::new(core),
        }
    }

    /// The port's name.
    pub fn name(&self) -> &str {
        &self.core.name
    }

    /// Publishes `value` to the port and every connected input.
    #[inline(always)]
    pub fn publish(&self, value: T) {
        let core = &*self.core;
        if core.local.try_publish(&value) {
            return;
        }
        // The other paths get a copy of their own. Handing them `&value` would let the
        // caller's value escape into a call, which keeps the optimiser from holding it in
        // registers on the fast path above (the value would cross the stack on its way
        // into the cell: a store-to-load forward more on every stage of a chain, b2).
        let detached = std::mem::MaybeUninit::new(value);
        core.publish_checked(&detached);
    }

    /// The last value published (or the initial value).
    pub fn get(&self) -> T {
        let core = &*self.core;
        core.local
            .get(&core.name)
            .unwrap_or_else(|| core.cell.load().0)
    }

    /// Number of connected inputs.
    pub fn connection_count(&self) -> usize {
        self.core.fanout.len()
    }

    /// Disconnects every input.
    pub fn disconnect_all(&self) {
        wiring::disconnect_all_targets(&self.core);
    }
}

impl<T: NoUninit + Send + Sync> Drop for CopyOutputPort<T> {
    fn drop(&mut self) {
        self.disconnect_all();
    }
}

impl<T: NoUninit + Send + Sync> fmt::Debug for CopyOutputPort<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("CopyOutputPort")
            .field("name", &self.core.name)
            .finish()
    }
}

impl<T: NoUninit + Send + Sync> CopyInputPort<T> {
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

    /// A queued input whose default value is `T::default()`.
    pub fn queued(name: impl Into<String>, queue: QueueConfig) -> Self
    where
        T: Default,
    {
        Self::build(name.into(), T::default(), Some(queue))
    }

    /// A queued input with the given default value.
    pub fn queued_with_default(name: impl Into<String>, queue: QueueConfig, value: T) -> Self {
        Self::build(name.into(), value, Some(queue))
    }

    fn build(name: String, value: T, queue: Option<QueueConfig>) -> Self {
        let core = CopyInputCore {
            name,
            cell: SeqCell::new(value),
            queue: queue.map(Queue::new),
            signal: Signal::new(),
            notifier: SetOnce::new(),
            input_sources: Mutex::new(InputSources {
                sources: Vec::new(),
                retained: (),
            }),
            local: LocalIn::new(),
        };
        CopyInputPort {
            core: Arc::new(core),
        }
    }

    /// The port's name.
    pub fn name(&self) -> &str {
        &self.core.name
    }

    /// The latest value delivered (or the default).
    #[inline]
    pub fn get(&self) -> T {
        self.core.read()
    }

    /// Has a value been delivered since the last [`take_changed`](Self::take_changed)?
    pub fn has_changed(&self) -> bool {
        self.core.has_changed()
    }

    /// Clears the changed mark and returns whether it was set.
    #[inline]
    pub fn take_changed(&self) -> bool {
        self.core.take_changed()
    }

    /// The queue settings, if this is a queued input.
    pub fn queue_config(&self) -> Option<QueueConfig> {
        self.core.queue.as_ref().map(Queue::config)
    }

    /// Number of values waiting in the queue.
    pub fn queued_len(&self) -> usize {
        self.core.queue.as_ref().map_or(0, Queue::len)
    }

    /// The oldest queued value, or for a latest-value input the current value if it
    /// changed since last taken; never waits.
    pub fn try_pop(&self) -> Option<T> {
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
    pub fn pop(&self) -> T {
        loop {
            if let Some(v) = self.pop_until(None) {
                return v;
            }
        }
    }

    /// Like [`pop`](Self::pop) with a time limit; `None` on timeout.
    pub fn pop_timeout(&self, timeout: Duration) -> Option<T> {
        self.pop_until(Some(Instant::now() + timeout))
    }

    fn pop_until(&self, deadline: Option<Instant>) -> Option<T> {
        loop {
            if let Some(v) = self.try_pop() {
                return Some(v);
            }
            let cell = &self.core.cell;
            let version = cell.version();
            let queue = self.core.queue.as_ref();
            let core = &*self.core;
            let ready = || match queue {
                Some(q) => q.len() != 0 || cell.version() != version,
                None => core.has_changed(),
            };
            if !self.core.signal.wait_data(ready, deadline) {
                return None;
            }
        }
    }

    /// Registers the notifier every delivery calls; gives it back if one is set.
    pub fn set_notifier(&self, notifier: Notifier) -> Result<(), Notifier> {
        self.core.notifier.set(notifier)
    }

    /// Number of connected outputs.
    pub fn connection_count(&self) -> usize {
        lock(&self.core.input_sources).sources.len()
    }

    /// A second reader of the latest value that leaves the changed mark alone.
    #[doc(hidden)]
    pub fn peek(&self) -> CopyPeek<T> {
        CopyPeek(Arc::clone(&self.core))
    }

    /// Disconnects every output.
    pub fn disconnect_all(&self) {
        wiring::disconnect_all_sources(&self.core);
    }
}

impl<T: NoUninit + Send + Sync> Drop for CopyInputPort<T> {
    fn drop(&mut self) {
        self.disconnect_all();
    }
}

impl<T: NoUninit + Send + Sync> fmt::Debug for CopyInputPort<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("CopyInputPort")
            .field("name", &self.core.name)
            .field("queue", &self.queue_config())
            .finish()
    }
}

impl<T: NoUninit + Send + Sync> CopyOutputCore<T> {
    /// A publish the fast path did not take: locally after checking the caller may,
    /// then on the lock-free path (the shared value, then every input that does not read
    /// a local cell) where needed. Kept out of line so the fast path stays small.
    #[inline(never)]
    fn publish_checked(&self, value: &std::mem::MaybeUninit<T>) {
        // SAFETY: every caller passes an initialised value.
        let value = unsafe { value.assume_init_read() };
        if !self.local.publish(&value, &self.name) {
            return;
        }
        self.cell.store(&value, false);
        let reader = self.fanout.snap.read();
        let mut deferred = Vec::new();
        for input in &reader.load().list {
            CopyInputCore::deliver(input, value, &mut deferred);
        }
        drop(reader);
        for input in deferred {
            input.deliver_blocking(self, value);
        }
    }
}

impl<T: NoUninit + Send + Sync> CopyInputCore<T> {
    fn deliver(this: &Arc<Self>, value: T, deferred: &mut Vec<Arc<Self>>) {
        if let Some(q) = &this.queue {
            if q.offer(value).is_err() {
                deferred.push(Arc::clone(this));
            }
        }
        this.cell.store(&value, true);
        this.delivered();
    }

    fn deliver_blocking(&self, out: &CopyOutputCore<T>, value: T) {
        let Some(q) = &self.queue else { return };
        let mut done = false;
        self.signal.wait_space(|| {
            done = q.push(value).is_ok();
            done || !wiring::is_source(self, out)
        });
        if done {
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

impl<T: NoUninit + Send + Sync> OutCore for CopyOutputCore<T> {
    type In = CopyInputCore<T>;

    fn name(&self) -> &str {
        &self.name
    }

    fn fanout(&self) -> &Fanout<CopyInputCore<T>> {
        &self.fanout
    }

    fn retain(&self, _retained: &mut ()) {}

    fn is_local(&self, input: &CopyInputCore<T>) -> bool {
        super::copy_local::is_local(self, input)
    }

    fn leave_local(
        out: &Arc<Self>,
        input: &Arc<CopyInputCore<T>>,
        keep: bool,
    ) -> Result<(), super::local::Busy> {
        super::copy_local::leave(out, input, keep)
    }

    fn local_pair(out: &Arc<Self>, input: &Arc<CopyInputCore<T>>) -> Option<super::LocalPair> {
        let (out, input) = (Arc::clone(out), Arc::clone(input));
        Some(Box::new(move |home| {
            super::copy_local::make_local(&out, &input, home)
        }))
    }

    fn initial_push(&self, input: &CopyInputCore<T>, mark: usize) {
        let (value, version) = self.cell.load();
        if !SeqCell::<T>::is_initial(version) && input.cell.replace_if(mark, &value) {
            input.delivered();
        }
    }
}

impl<T: NoUninit + Send + Sync> InCore for CopyInputCore<T> {
    type Out = CopyOutputCore<T>;
    type Retained = ();
    type Mark = usize;

    fn name(&self) -> &str {
        &self.name
    }

    fn input_sources(&self) -> &Mutex<InputSources<CopyOutputCore<T>, ()>> {
        &self.input_sources
    }

    fn refs_per_delivery(&self) -> usize {
        0
    }

    fn is_queued(&self) -> bool {
        self.queue.is_some()
    }

    fn mark(&self) -> usize {
        self.cell.version()
    }

    fn wake_producers(&self) {
        self.signal.notify_space();
    }
}

impl<T: NoUninit + Send + Sync> super::handle::HasNotifier for CopyInputCore<T> {
    fn set_notifier(&self, notifier: Notifier) -> Result<(), Notifier> {
        self.notifier.set(notifier)
    }
}
