//! Input queues (`queue=N`, `on-full=…`) and the waiting that goes with them.
//!
//! The FIFO itself is lock-free ([`crossbeam_queue::ArrayQueue`], allocated once): with
//! `drop-oldest` or `drop-newest` a publisher never waits. Only `block` makes a
//! publisher wait for space, and only blocking reads make a consumer wait for data;
//! both wait on a [`Signal`], which publishers and consumers touch only when its waiter
//! count says someone is waiting (one SeqCst load on the fast path).

use std::time::{Duration, Instant};

use crate::sync::{fence, lock, AtomicUsize, Condvar, Mutex, Ordering};

/// What a full input queue does with a new value (`on-full=`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum OnFull {
    /// The publisher waits until the consumer makes room (or the connection goes away).
    Block,
    /// The oldest queued value is dropped to make room (the default).
    #[default]
    DropOldest,
    /// The new value is dropped for this input.
    DropNewest,
}

/// A bounded FIFO for an input port: `queue=capacity`, `on-full=on_full`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct QueueConfig {
    /// Maximum number of queued values (at least 1).
    pub capacity: usize,
    /// Overflow policy.
    pub on_full: OnFull,
}

impl QueueConfig {
    /// A queue of `capacity` values (raised to 1 if 0) with the default `drop-oldest`.
    pub fn new(capacity: usize) -> Self {
        QueueConfig {
            capacity: capacity.max(1),
            on_full: OnFull::default(),
        }
    }

    /// The same queue with another overflow policy.
    pub fn on_full(mut self, on_full: OnFull) -> Self {
        self.on_full = on_full;
        self
    }
}

#[cfg(not(loom))]
type Fifo<E> = crossbeam_queue::ArrayQueue<E>;
#[cfg(loom)]
type Fifo<E> = loom_fifo::Fifo<E>;

/// The FIFO plus its policy.
pub(crate) struct Queue<E> {
    fifo: Fifo<E>,
    config: QueueConfig,
}

impl<E> Queue<E> {
    pub(crate) fn new(config: QueueConfig) -> Self {
        let config = QueueConfig::new(config.capacity).on_full(config.on_full);
        Queue {
            fifo: Fifo::new(config.capacity),
            config,
        }
    }

    pub(crate) fn config(&self) -> QueueConfig {
        self.config
    }

    /// The non-blocking part of a delivery. Values dropped by the policy are dropped
    /// here. `Err` gives the value back only under [`OnFull::Block`] when full.
    pub(crate) fn offer(&self, item: E) -> Result<(), E> {
        match self.config.on_full {
            OnFull::DropOldest => {
                drop(self.fifo.force_push(item));
                Ok(())
            }
            OnFull::DropNewest => {
                drop(self.fifo.push(item));
                Ok(())
            }
            OnFull::Block => self.fifo.push(item),
        }
    }

    pub(crate) fn push(&self, item: E) -> Result<(), E> {
        self.fifo.push(item)
    }

    pub(crate) fn pop(&self) -> Option<E> {
        self.fifo.pop()
    }

    pub(crate) fn len(&self) -> usize {
        self.fifo.len()
    }
}

/// How long a publisher blocked on a full queue sleeps before re-checking on its own.
/// Wakeups are not lost (see [`Signal`]); this only bounds the damage of a bug.
const BLOCK_BACKSTOP: Duration = Duration::from_millis(100);

/// Wait/notify for one input: consumers waiting for data, publishers waiting for space.
///
/// Lost wakeups are excluded the usual way: a waiter registers (SeqCst increment, SeqCst
/// fence), then re-checks its condition under the mutex, then sleeps (which releases the
/// mutex atomically); a notifier changes the condition first, then (SeqCst) reads the
/// waiter count and, if non-zero, notifies under the mutex.
pub(crate) struct Signal {
    lock: Mutex<()>,
    data: Condvar,
    space: Condvar,
    data_waiters: AtomicUsize,
    space_waiters: AtomicUsize,
}

impl Signal {
    pub(crate) fn new() -> Self {
        Signal {
            lock: Mutex::new(()),
            data: Condvar::new(),
            space: Condvar::new(),
            data_waiters: AtomicUsize::new(0),
            space_waiters: AtomicUsize::new(0),
        }
    }

    /// After a delivery; the delivery's SeqCst store is the "condition changed".
    pub(crate) fn notify_data(&self) {
        if self.data_waiters.load(Ordering::SeqCst) != 0 {
            let _g = lock(&self.lock);
            self.data.notify_all();
        }
    }

    /// After a pop from a `block` queue, or when a connection goes away.
    pub(crate) fn notify_space(&self) {
        fence(Ordering::SeqCst);
        if self.space_waiters.load(Ordering::SeqCst) != 0 {
            let _g = lock(&self.lock);
            self.space.notify_all();
        }
    }

    /// Waits until `ready()` or the deadline; false if the deadline passed first.
    pub(crate) fn wait_data(&self, ready: impl FnMut() -> bool, deadline: Option<Instant>) -> bool {
        self.wait(&self.data, &self.data_waiters, ready, deadline, None)
    }

    /// Waits until `ready()` (which tries the push and checks the connection), or
    /// until the application running on this thread is asked to stop (seen within
    /// [`BLOCK_BACKSTOP`]): a write into a queue nobody drains must not keep a run
    /// from ending. The caller then drops the value.
    pub(crate) fn wait_space(&self, mut ready: impl FnMut() -> bool) {
        self.wait(
            &self.space,
            &self.space_waiters,
            || ready() || crate::stopping::requested(),
            None,
            Some(BLOCK_BACKSTOP),
        );
    }

    fn wait(
        &self,
        cv: &Condvar,
        waiters: &AtomicUsize,
        mut ready: impl FnMut() -> bool,
        deadline: Option<Instant>,
        backstop: Option<Duration>,
    ) -> bool {
        let mut guard = lock(&self.lock);
        waiters.fetch_add(1, Ordering::SeqCst);
        fence(Ordering::SeqCst);
        let result = loop {
            if ready() {
                break true;
            }
            let timeout = match deadline {
                Some(d) => {
                    let now = Instant::now();
                    if now >= d {
                        break false;
                    }
                    Some(d - now)
                }
                None => backstop,
            };
            guard = match timeout {
                None => cv.wait(guard).unwrap_or_else(|e| e.into_inner()),
                Some(t) => match cv.wait_timeout(guard, t) {
                    Ok((g, _)) => g,
                    Err(e) => e.into_inner().0,
                },
            };
        };
        waiters.fetch_sub(1, Ordering::SeqCst);
        result
    }
}

/// Under loom the FIFO is a mutex around a `VecDeque` with the same interface: loom
/// cannot see inside crossbeam, and the queue policies (not the FIFO) are what the loom
/// tests check.
#[cfg(loom)]
mod loom_fifo {
    use std::collections::VecDeque;

    use crate::sync::{lock, Mutex};

    pub(crate) struct Fifo<E> {
        items: Mutex<VecDeque<E>>,
        capacity: usize,
    }

    impl<E> Fifo<E> {
        pub(crate) fn new(capacity: usize) -> Self {
            Fifo {
                items: Mutex::new(VecDeque::with_capacity(capacity)),
                capacity,
            }
        }
        pub(crate) fn push(&self, item: E) -> Result<(), E> {
            let mut q = lock(&self.items);
            if q.len() == self.capacity {
                return Err(item);
            }
            q.push_back(item);
            Ok(())
        }
        pub(crate) fn force_push(&self, item: E) -> Option<E> {
            let mut q = lock(&self.items);
            let old = if q.len() == self.capacity {
                q.pop_front()
            } else {
                None
            };
            q.push_back(item);
            old
        }
        pub(crate) fn pop(&self) -> Option<E> {
            lock(&self.items).pop_front()
        }
        pub(crate) fn len(&self) -> usize {
            lock(&self.items).len()
        }
    }
}
