//! [`PortRef`]: the reader's zero-copy handle to a published buffer.

use std::fmt;
use std::marker::PhantomData;
use std::ops::Deref;
use std::ptr::NonNull;

use super::pool::{self, Slot};

/// A shared, immutable reference to a value published on a port.
///
/// Cloning it and dropping it only touch the buffer's reference count; the value is
/// never copied. When the last holder (reader, port, queue entry) lets go, the buffer
/// goes back to its output port's pool for reuse. A `PortRef` may outlive the ports it
/// came from.
pub struct PortRef<T> {
    slot: NonNull<Slot<T>>,
    _owns: PhantomData<T>,
}

// SAFETY: a PortRef hands out `&T` to any thread (needs T: Sync) and its last drop may
// hand the buffer to another thread for reuse or drop T there (needs T: Send) — the
// same bounds as `Arc<T>`.
unsafe impl<T: Send + Sync> Send for PortRef<T> {}
// SAFETY: see above.
unsafe impl<T: Send + Sync> Sync for PortRef<T> {}

impl<T> PortRef<T> {
    /// Adopts one reference the caller owns.
    ///
    /// # Safety
    /// The caller owns one reference of a published slot and transfers it.
    pub(crate) unsafe fn from_raw(slot: NonNull<Slot<T>>) -> Self {
        PortRef {
            slot,
            _owns: PhantomData,
        }
    }

    /// Gives up ownership of the reference without releasing it.
    pub(crate) fn into_raw(self) -> NonNull<Slot<T>> {
        let slot = self.slot;
        std::mem::forget(self);
        slot
    }

    /// Address of the slot, for version comparisons.
    pub(crate) fn addr(&self) -> usize {
        self.slot.as_ptr().addr()
    }

    /// Do both references point at the same buffer (the same published value)?
    pub fn ptr_eq(a: &Self, b: &Self) -> bool {
        a.slot == b.slot
    }
}

impl<T> Deref for PortRef<T> {
    type Target = T;
    fn deref(&self) -> &T {
        // SAFETY: we hold a reference (refs > 0), so the slot is published and nobody
        // writes the value until every reference, ours included, is gone.
        unsafe { &*Slot::value_ptr(self.slot) }
    }
}

impl<T> std::borrow::Borrow<T> for PortRef<T> {
    fn borrow(&self) -> &T {
        self
    }
}

impl<T> Clone for PortRef<T> {
    fn clone(&self) -> Self {
        // SAFETY: our own reference keeps the slot live.
        unsafe { Slot::add_refs(self.slot, 1) };
        PortRef {
            slot: self.slot,
            _owns: PhantomData,
        }
    }
}

impl<T> Drop for PortRef<T> {
    fn drop(&mut self) {
        // SAFETY: we own exactly one reference and give it up.
        unsafe { pool::release(self.slot, 1) }
    }
}

impl<T: fmt::Debug> fmt::Debug for PortRef<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(&**self, f)
    }
}

impl<T: PartialEq> PartialEq for PortRef<T> {
    fn eq(&self, other: &Self) -> bool {
        **self == **other
    }
}

/// A buffer taken from an output port's pool, writable until published.
///
/// It holds whatever value the buffer had when it was last used (or the port's initial
/// value), so it can be updated in place. Dropping it without
/// [`publish`](Self::publish) returns it to the pool unpublished.
pub struct BufferMut<'a, T: Send + Sync + 'static> {
    pub(crate) slot: NonNull<Slot<T>>,
    pub(crate) port: &'a super::output::OutputCore<T>,
}

impl<T: Send + Sync + 'static> BufferMut<'_, T> {
    /// Publishes the buffer: one atomic swap makes it the port's value, then it is
    /// delivered to every connected input.
    pub fn publish(self) {
        let slot = self.slot;
        let port = self.port;
        std::mem::forget(self);
        port.publish_slot(slot);
    }
}

impl<T: Send + Sync + 'static> Deref for BufferMut<'_, T> {
    type Target = T;
    fn deref(&self) -> &T {
        // SAFETY: the slot is owned exclusively by this BufferMut (refs == 0, off the
        // free list), so no one else reads or writes it.
        unsafe { &*Slot::value_ptr(self.slot) }
    }
}

impl<T: Send + Sync + 'static> std::ops::DerefMut for BufferMut<'_, T> {
    fn deref_mut(&mut self) -> &mut T {
        // SAFETY: exclusive ownership, see `deref`.
        unsafe { &mut *Slot::value_ptr(self.slot) }
    }
}

impl<T: Send + Sync + 'static> Drop for BufferMut<'_, T> {
    fn drop(&mut self) {
        // SAFETY: exclusively owned and never published: straight back to the pool.
        unsafe { pool::recycle(self.slot) }
    }
}
