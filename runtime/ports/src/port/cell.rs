//! [`ValueCell`]: the "current value" of a port, one atomic word.
//!
//! The word is a pointer to a slot, tagged in its lowest bit with *changed* (set by
//! deliveries, cleared by the reader). The cell always owns exactly one reference of the
//! slot it points to. Storing swaps the word and releases the old slot's reference;
//! reading is:
//!
//! 1. load the word (the slot may be replaced and even recycled right after);
//! 2. take a reference with [`try_retain`] — it only succeeds while the slot is
//!    published, so a recycled buffer being refilled is never returned;
//! 3. check that the word still points to the same slot. If it does, the reference we
//!    hold is the cell's current value (a slot is published at most once at a time, and
//!    the cell holds it, so it cannot be a different incarnation). Otherwise drop it and
//!    retry: the value changed under us, and the slot we got may be a later reuse.
//!
//! Step 2 touches a slot that may no longer be referenced by anyone, which is sound only
//! because pool memory is type-stable: the owner of a cell keeps a
//! [`PoolHandle`](super::pool::PoolHandle) of every pool whose slots it may receive.
//! That is the contract of [`ValueCell::store`].

use std::marker::PhantomData;
use std::ptr::NonNull;

use super::pool::{self, Slot};
use super::PortRef;
use crate::sync::{spin_loop, AtomicPtr, Ordering};

const CHANGED: usize = 1;

pub(crate) struct ValueCell<T> {
    word: AtomicPtr<Slot<T>>,
    /// Auto traits follow `PortRef<T>` (the cell owns one).
    _owns: PhantomData<PortRef<T>>,
}

fn untag<T>(p: *mut Slot<T>) -> NonNull<Slot<T>> {
    let p = p.map_addr(|a| a & !CHANGED);
    NonNull::new(p).unwrap_or_else(|| unreachable!("a value cell is never empty"))
}

impl<T> ValueCell<T> {
    /// A cell holding `initial` (its reference moves into the cell), not marked changed.
    pub(crate) fn new(initial: PortRef<T>) -> Self {
        ValueCell {
            word: AtomicPtr::new(initial.into_raw().as_ptr()),
            _owns: PhantomData,
        }
    }

    /// Makes `value` the current value, marking it changed or not, and returns the raw
    /// word it replaced (for [`Self::replace_if`] callers that track versions).
    ///
    /// SeqCst: for deliveries, the swap is ordered before the publisher's check for
    /// blocked readers (see `queue::Signal`). On x86 it costs the same as AcqRel.
    ///
    /// # Safety
    /// The pool of `value`'s slot must be kept alive (a handle retained by the owner of
    /// this cell) for as long as [`Self::get`] may be called on it.
    pub(crate) unsafe fn store(&self, value: PortRef<T>, changed: bool) {
        let new = value
            .into_raw()
            .as_ptr()
            .map_addr(|a| a | if changed { CHANGED } else { 0 });
        let old = self.word.swap(new, Ordering::SeqCst);
        // SAFETY: the cell owned one reference of the old slot.
        unsafe { pool::release(untag(old), 1) }
    }

    /// Stores `value` only if the word is still `expected` (as returned by
    /// [`Self::version`]); used for the initial push at connect time, which must never
    /// overwrite a value delivered after the connection became visible.
    ///
    /// # Safety
    /// As for [`Self::store`].
    pub(crate) unsafe fn replace_if(&self, expected: usize, value: PortRef<T>) -> bool {
        let new = value.into_raw().as_ptr().map_addr(|a| a | CHANGED);
        let current = self.word.load(Ordering::SeqCst);
        if current.addr() != expected {
            // SAFETY: we own the reference we were given and did not store it.
            unsafe { pool::release(untag(new), 1) };
            return false;
        }
        match self
            .word
            .compare_exchange(current, new, Ordering::SeqCst, Ordering::SeqCst)
        {
            Ok(old) => {
                // SAFETY: the cell owned one reference of the old slot.
                unsafe { pool::release(untag(old), 1) };
                true
            }
            Err(_) => {
                // SAFETY: as above, ours and unstored.
                unsafe { pool::release(untag(new), 1) };
                false
            }
        }
    }

    /// An opaque version of the current value: it changes with every store.
    pub(crate) fn version(&self) -> usize {
        self.word.load(Ordering::SeqCst).addr()
    }

    /// The current version together with a reference to the value it names. Holding the
    /// reference keeps that slot from being recycled, so the version cannot recur
    /// (no ABA) while the caller compares against it.
    pub(crate) fn mark(&self) -> (usize, PortRef<T>) {
        loop {
            let version = self.version();
            let held = self.get();
            if version & !CHANGED == held.addr() {
                return (version, held);
            }
        }
    }

    /// A reference to the current value (see the module docs for the protocol).
    pub(crate) fn get(&self) -> PortRef<T> {
        loop {
            let slot = untag(self.word.load(Ordering::Acquire));
            // SAFETY: type-stable pool memory, guaranteed by `store`'s contract.
            if unsafe { pool::try_retain(slot) } {
                // SAFETY: try_retain gave us one reference.
                let held = unsafe { PortRef::from_raw(slot) };
                if untag(self.word.load(Ordering::Acquire)) == slot {
                    return held;
                }
            }
            spin_loop();
        }
    }

    /// Was a value delivered since the last [`Self::take_changed`]?
    pub(crate) fn has_changed(&self) -> bool {
        self.word.load(Ordering::SeqCst).addr() & CHANGED != 0
    }

    /// Clears the changed mark, returning whether it was set.
    pub(crate) fn take_changed(&self) -> bool {
        let mut cur = self.word.load(Ordering::SeqCst);
        loop {
            if cur.addr() & CHANGED == 0 {
                return false;
            }
            let cleared = cur.map_addr(|a| a & !CHANGED);
            match self
                .word
                .compare_exchange_weak(cur, cleared, Ordering::SeqCst, Ordering::SeqCst)
            {
                Ok(_) => return true,
                Err(actual) => cur = actual,
            }
        }
    }
}

impl<T> Drop for ValueCell<T> {
    fn drop(&mut self) {
        let slot = untag(self.word.load(Ordering::Acquire));
        // SAFETY: the cell owns one reference of its slot.
        unsafe { pool::release(slot, 1) }
    }
}
