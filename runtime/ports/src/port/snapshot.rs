//! [`Snapshot`]: a copy-on-write value that publishers read without locks and that
//! connect/disconnect replace without ever waiting for publishers.
//!
//! Used for an output's list of connected inputs. Readers register in a counter, load
//! the current pointer and use it; a writer (serialised by a mutex) swaps in a new
//! value and *retires* the old one onto a garbage list instead of freeing it. Garbage
//! is freed by whoever sees the reader count at zero — the writer right after retiring,
//! or the last reader leaving — following this rule:
//!
//! > take the whole garbage list, then re-check that the reader count is still zero;
//! > if it is, free the list, otherwise put it back.
//!
//! Why that is enough: a reader that can still use a retired value `V` loaded it before
//! the swap that retired it, so it registered before that swap, and the swap happened
//! before `V` was put on the garbage list, which happened before the list was taken.
//! So at the re-check that reader is either still counted (nothing is freed) or gone.
//! The collector reads the count with a read-modify-write (always the latest value, and
//! it synchronises with every registration ordered before it), so this "before" holds
//! in the plain acquire/release model, not only under SeqCst. An earlier version read
//! the count with a SeqCst load; loom, which models SeqCst more weakly than C++, found a
//! use-after-free with it.
//!
//! Publishers never block and never allocate here (two atomic read-modify-writes per
//! read); writers never wait for readers (a publisher blocked on a full queue only
//! delays freeing garbage, not a disconnect).

use std::ptr;

use crate::sync::{lock, AtomicPtr, AtomicUsize, Mutex, MutexGuard, Ordering};

struct Node<V> {
    value: V,
    /// Next retired node while on the garbage list.
    next: AtomicPtr<Node<V>>,
    /// Under loom: read on every use, written when freed, so loom reports a node freed
    /// while a reader may still use it (a causality violation) instead of hoping for a
    /// crash.
    #[cfg(loom)]
    alive: loom::cell::UnsafeCell<()>,
}

impl<V> Node<V> {
    fn touch(&self) {
        #[cfg(loom)]
        self.alive.with(|_| ());
    }

    /// Frees a node owned by the caller.
    ///
    /// # Safety
    /// `node` came from [`boxed`] and nobody can use it any more.
    unsafe fn free(node: *mut Node<V>) -> *mut Node<V> {
        // SAFETY: caller's contract.
        let owned = unsafe { Box::from_raw(node) };
        #[cfg(loom)]
        owned.alive.with_mut(|_| ());
        owned.next.load(Ordering::Relaxed)
    }
}

pub(crate) struct Snapshot<V> {
    current: AtomicPtr<Node<V>>,
    readers: AtomicUsize,
    garbage: AtomicPtr<Node<V>>,
    write: Mutex<()>,
}

fn boxed<V>(value: V) -> *mut Node<V> {
    Box::into_raw(Box::new(Node {
        value,
        next: AtomicPtr::new(ptr::null_mut()),
        #[cfg(loom)]
        alive: loom::cell::UnsafeCell::new(()),
    }))
}

impl<V> Snapshot<V> {
    pub(crate) fn new(value: V) -> Self {
        Snapshot {
            current: AtomicPtr::new(boxed(value)),
            readers: AtomicUsize::new(0),
            garbage: AtomicPtr::new(ptr::null_mut()),
            write: Mutex::new(()),
        }
    }

    /// Registers a reader. Every value loaded through the guard stays valid until the
    /// guard is dropped.
    pub(crate) fn read(&self) -> ReadGuard<'_, V> {
        self.readers.fetch_add(1, Ordering::SeqCst);
        ReadGuard { snap: self }
    }

    /// Exclusive access for replacing the value (connect/disconnect).
    pub(crate) fn write(&self) -> WriteGuard<'_, V> {
        WriteGuard {
            snap: self,
            _lock: lock(&self.write),
        }
    }

    /// Pushes a chain `first ..= last` of retired nodes onto the garbage list.
    fn push_garbage(&self, first: *mut Node<V>, last: *mut Node<V>) {
        let mut head = self.garbage.load(Ordering::SeqCst);
        loop {
            // SAFETY: the chain is owned by the caller until the CAS publishes it.
            unsafe { (*last).next.store(head, Ordering::Relaxed) };
            match self.garbage.compare_exchange_weak(
                head,
                first,
                Ordering::SeqCst,
                Ordering::SeqCst,
            ) {
                Ok(_) => return,
                Err(actual) => head = actual,
            }
        }
    }

    /// The reader count, read with a read-modify-write: an RMW always sees the latest
    /// value and synchronises with the registrations before it, so the argument in the
    /// module docs holds even without relying on SeqCst loads (which loom does not
    /// model exactly).
    fn readers_now(&self) -> usize {
        self.readers.fetch_add(0, Ordering::SeqCst)
    }

    /// Frees the garbage if no reader is registered (see the module docs).
    fn collect(&self) {
        if self.readers_now() != 0 {
            return;
        }
        let first = self.garbage.swap(ptr::null_mut(), Ordering::SeqCst);
        if first.is_null() {
            return;
        }
        if self.readers_now() != 0 {
            // Someone registered meanwhile and may use a node of this list: put it back.
            let mut last = first;
            // SAFETY: the taken chain is ours; walk to its end.
            while let Some(next) = unsafe { (*last).next.load(Ordering::Relaxed).as_mut() } {
                last = next;
            }
            self.push_garbage(first, last);
            return;
        }
        let mut node = first;
        while !node.is_null() {
            // SAFETY: retired, taken by us, and no reader can still use it.
            node = unsafe { Node::free(node) };
        }
    }
}

impl<V> Drop for Snapshot<V> {
    fn drop(&mut self) {
        // `&mut self`: no reader or writer is left.
        let current = self.current.load(Ordering::Relaxed);
        // SAFETY: the current node came from `boxed` and is owned by the snapshot.
        unsafe { Node::free(current) };
        let mut node = self.garbage.load(Ordering::Relaxed);
        while !node.is_null() {
            // SAFETY: retired nodes are owned by the garbage list.
            node = unsafe { Node::free(node) };
        }
    }
}

pub(crate) struct ReadGuard<'a, V> {
    snap: &'a Snapshot<V>,
}

impl<V> ReadGuard<'_, V> {
    /// The current value. SeqCst: ordered after the caller's earlier SeqCst stores
    /// (publish stores the output's value first, then loads the inputs to deliver to).
    pub(crate) fn load(&self) -> &V {
        let node = self.snap.current.load(Ordering::SeqCst);
        // SAFETY: nodes loaded while registered are not freed before we unregister.
        let node = unsafe { &*node };
        node.touch();
        &node.value
    }
}

impl<V> Drop for ReadGuard<'_, V> {
    fn drop(&mut self) {
        if self.snap.readers.fetch_sub(1, Ordering::SeqCst) == 1
            && !self.snap.garbage.load(Ordering::SeqCst).is_null()
        {
            self.snap.collect();
        }
    }
}

pub(crate) struct WriteGuard<'a, V> {
    snap: &'a Snapshot<V>,
    _lock: MutexGuard<'a, ()>,
}

impl<V> WriteGuard<'_, V> {
    /// The current value (stable while the guard is held: only writers replace it).
    pub(crate) fn get(&self) -> &V {
        let node = self.snap.current.load(Ordering::SeqCst);
        // SAFETY: only writers retire nodes and we are the writer.
        unsafe { &(*node).value }
    }

    /// Publishes a new value; the old one is freed once no reader can use it.
    ///
    /// Always ends with an RMW of the reader count (in `collect`): a publisher that
    /// registers after it sees the new value, and one registered before it has its
    /// earlier stores (the port's new value) visible to us — the initial push relies
    /// on that (see `wiring::connect`).
    pub(crate) fn replace(&mut self, value: V) {
        let old = self.snap.current.swap(boxed(value), Ordering::SeqCst);
        self.snap.push_garbage(old, old);
        self.snap.collect();
    }
}
