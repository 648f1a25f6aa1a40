//! The local path of the copy ports (`local.rs` explains the rules): an output keeps
//! its value in a plain cell, and an input connected inside the container reads that
//! cell directly instead of receiving a copy.

use std::ptr;

use super::copy::{CopyInputCore, CopyOutputCore};
use super::local::{self, Busy, Exclusive, Home};
use super::notify::SetOnce;
use super::words;
use crate::sync::{lock, Arc, AtomicBool, AtomicPtr, AtomicUsize, Mutex, Ordering, UnsafeCell};
use bytemuck::NoUninit;

/// An output's local side.
pub(crate) struct LocalOut<T> {
    /// The home of its local connections; null while it has none (then every publish
    /// takes the lock-free path). Set once, by [`localize`].
    home: AtomicPtr<Home>,
    /// Keeps that home alive (and with it the address `home` names).
    keep_home: SetOnce<Arc<Home>>,
    /// The value, touched only by the home's session or an [`Exclusive`] holder.
    value: UnsafeCell<T>,
    /// Local publishes so far (the same rule): inputs compare it with what they saw.
    version: UnsafeCell<u64>,
    /// The mark of the thread that may publish by the fast path: the session thread of
    /// `home` while the output publishes only locally (registered with the home, which
    /// opens and closes it with its sessions: [`Home::set_gate`]); 0 otherwise. Every
    /// other case (no local readers, `both`, another thread) takes the checked path.
    gate: AtomicUsize,
    /// Publish on the lock-free path as well: some reader does not read `value`
    /// directly. Only ever set during a run (by [`share`]); cleared only by
    /// [`localize`], under the output's connection lock.
    both: AtomicBool,
}

/// What an input reading its output directly remembers (touched like `LocalOut::value`).
#[derive(Clone, Copy, Default)]
struct Seen {
    /// The output's version when the connection became local: until it changes, the
    /// input's own cell still holds the right value (its default, or the last delivery).
    from: u64,
    /// The version the last `take_changed` saw.
    seen: u64,
    /// A delivery not yet taken when the connection became local.
    pending: bool,
}

/// An input's local side.
pub(crate) struct LocalIn<T: NoUninit + Send + Sync> {
    /// The output this input reads directly; null: it reads its own cell.
    src: AtomicPtr<CopyOutputCore<T>>,
    /// Every output it ever read directly, kept alive for the input's lifetime: a thread
    /// may still load `src` and look at that output's home after the connection changed.
    keep: Mutex<Vec<Arc<CopyOutputCore<T>>>>,
    seen: UnsafeCell<Seen>,
}

// SAFETY: the cells are touched only by the thread holding the session of the home
// named by `home` (checked on every access) or by an `Exclusive` holder, whom the home
// orders with its sessions (local.rs); `T: Send + Sync` as for the lock-free path.
unsafe impl<T: NoUninit + Send + Sync> Sync for LocalOut<T> {}
// SAFETY: see above.
unsafe impl<T: NoUninit + Send + Sync> Sync for LocalIn<T> {}

impl<T: NoUninit> LocalOut<T> {
    pub(crate) fn new(value: T) -> Self {
        LocalOut {
            home: AtomicPtr::new(ptr::null_mut()),
            keep_home: SetOnce::new(),
            value: UnsafeCell::new(value),
            version: UnsafeCell::new(0),
            gate: AtomicUsize::new(0),
            both: AtomicBool::new(false),
        }
    }

    /// The fast path of a publish: stores `value` locally and returns true when the
    /// caller is the thread the gate is open for (the output has only local readers).
    /// One load and a compare before the store.
    #[inline(always)]
    pub(crate) fn try_publish(&self, value: &T) -> bool {
        if self.gate.load(Ordering::Relaxed) != local::mark() {
            return false;
        }
        // SAFETY: only the session thread of the cell's home finds its mark in the gate
        // (`Home::set_gate`).
        unsafe { self.store(value) };
        true
    }

    /// Publishes locally if the output has local readers, after checking the caller
    /// may. Returns whether the lock-free path is still to be taken.
    #[allow(clippy::ptr_arg)] // see `local::foreign_access`
    pub(crate) fn publish(&self, value: &T, port: &String) -> bool {
        let home = self.home.load(Ordering::Acquire);
        if home.is_null() {
            return true;
        }
        // SAFETY: a home stored in `home` is kept alive by `keep_home` as long as we are.
        if !unsafe { (*home).is_owner() } {
            local::foreign_access(port);
        }
        // SAFETY: this thread holds the session of the cell's home (checked above).
        unsafe { self.store(value) };
        self.both.load(Ordering::Relaxed)
    }

    /// # Safety
    /// The caller holds the session of the cell's home.
    #[inline(always)]
    unsafe fn store(&self, value: &T) {
        // SAFETY: caller's contract.
        unsafe {
            self.value.with_mut(|p| words::copy(value, p));
            self.version.with_mut(|p| *p += 1);
        }
    }

    /// The output's own latest value if it has local readers (`None`: read the shared
    /// cell).
    #[inline]
    #[allow(clippy::ptr_arg)] // see `local::foreign_access`
    pub(crate) fn get(&self, port: &String) -> Option<T> {
        let home = self.home.load(Ordering::Acquire);
        if home.is_null() {
            return None;
        }
        // SAFETY: as in `publish`.
        if !unsafe { (*home).is_owner() } {
            local::foreign_access(port);
        }
        // SAFETY: session thread of the cell's home (checked above).
        Some(unsafe { self.value.with(|p| *p) })
    }

    /// Panics unless the caller holds the session of the output's home (the gate
    /// did not say so: it is closed while the output publishes on both paths).
    #[cold]
    #[inline(never)]
    #[allow(clippy::ptr_arg)] // see `local::foreign_access`
    fn check_owner(&self, port: &String) {
        // Relaxed: the home was set before the input's `src` was stored, and the load of
        // `src` acquired it. Non-null for the same reason; kept alive by `keep_home`.
        let home = self.home.load(Ordering::Relaxed);
        // SAFETY: see above.
        if !unsafe { (*home).is_owner() } {
            local::foreign_access(port);
        }
    }

    fn home(&self) -> Option<Arc<Home>> {
        self.keep_home.get().cloned()
    }

    /// Read by the session thread or an `Exclusive` holder of the home.
    ///
    /// # Safety
    ///
    /// The caller holds the session of the output's home or an `Exclusive` proof of
    /// it: no other thread writes the version meanwhile.
    unsafe fn version(&self) -> u64 {
        // SAFETY: caller's contract.
        unsafe { self.version.with(|p| *p) }
    }
}

impl<T> Drop for LocalOut<T> {
    fn drop(&mut self) {
        // The home must forget the gate before it goes.
        if let Some(home) = self.keep_home.get() {
            home.set_gate(&self.gate, false);
        }
    }
}

impl<T: NoUninit + Send + Sync> LocalIn<T> {
    pub(crate) fn new() -> Self {
        LocalIn {
            src: AtomicPtr::new(ptr::null_mut()),
            keep: Mutex::new(Vec::new()),
            seen: UnsafeCell::new(Seen::default()),
        }
    }

    /// The output read directly, after checking that this thread may read it; `None`
    /// when the input reads its own cell.
    #[inline(always)]
    #[allow(clippy::ptr_arg)] // see `local::foreign_access`
    fn source(&self, port: &String) -> Option<&CopyOutputCore<T>> {
        let src = self.src.load(Ordering::Acquire);
        if src.is_null() {
            return None;
        }
        // SAFETY: every output stored in `src` is kept alive by `keep` as long as we are.
        let src = unsafe { &*src };
        if src.local.gate.load(Ordering::Relaxed) != local::mark() {
            src.local.check_owner(port);
        }
        Some(src)
    }
}

impl<T: NoUninit + Send + Sync> CopyInputCore<T> {
    /// The latest value: the output's local cell once it published since the
    /// connection became local, else the input's own cell.
    #[inline(always)]
    pub(crate) fn read(&self) -> T {
        // Both paths give a place to copy from, and the value is copied once, from
        // there: the caller's variable is then written by that one copy (and stays in
        // registers where the optimiser can keep it), not merged from two copies through
        // a slot on the stack. The lock-free path fills a place of its own out of line.
        let mut shared = std::mem::MaybeUninit::uninit();
        let from: *const T = match self.local.source(&self.name) {
            // SAFETY: `source` checked that this thread holds the session of the home
            // both cells belong to.
            Some(src) if unsafe { src.local.version() != self.local.seen.with(|p| (*p).from) } => {
                src.local.value.with(|p| p)
            }
            _ => {
                self.read_shared(&mut shared);
                shared.as_ptr()
            }
        };
        let mut value = std::mem::MaybeUninit::uninit();
        // SAFETY: `from` is the local cell (this thread holds its home's session, and
        // nothing else touches it until we return) or `shared`, initialised above.
        // Under loom the cell's access is recorded by `with` above; nothing between it
        // and this read can switch threads, so the check covers the read.
        unsafe {
            words::copy(from, value.as_mut_ptr());
            value.assume_init()
        }
    }

    /// The input's own cell (the lock-free path).
    #[inline(never)]
    fn read_shared(&self, into: &mut std::mem::MaybeUninit<T>) {
        into.write(self.cell.load().0);
    }

    /// Clears the changed mark and returns whether it was set.
    #[inline]
    pub(crate) fn take_changed(&self) -> bool {
        match self.local.source(&self.name) {
            // SAFETY: session thread of the home (checked by `source`).
            Some(src) => unsafe {
                let version = src.local.version();
                self.local.seen.with_mut(|p| {
                    let seen = &mut *p;
                    let changed = seen.pending || seen.seen != version;
                    seen.seen = version;
                    seen.pending = false;
                    changed
                })
            },
            None => self.cell.take_changed(),
        }
    }

    /// Whether a value arrived that `take_changed` did not take yet.
    pub(crate) fn has_changed(&self) -> bool {
        match self.local.source(&self.name) {
            // SAFETY: session thread of the home (checked by `source`).
            Some(src) => unsafe {
                let version = src.local.version();
                self.local
                    .seen
                    .with(|p| (*p).pending || (*p).seen != version)
            },
            None => self.cell.has_changed(),
        }
    }
}

/// Makes `out → inp` local to `home` if it can be: connected, the input not queued and
/// fed by `out` alone, the output local to no other home. False leaves it lock-free.
pub(crate) fn localize<T: NoUninit + Send + Sync>(
    proof: &Exclusive<'_>,
    home: &Arc<Home>,
    out: &Arc<CopyOutputCore<T>>,
    inp: &Arc<CopyInputCore<T>>,
) -> bool {
    let home_ptr = Arc::as_ptr(home).cast_mut();
    if !proof.covers(home_ptr) {
        return false;
    }
    // The connection locks, in wiring's order: a connect elsewhere sees the result
    // whole (see `wiring::connect`).
    let writer = out.fanout.snap.write();
    if !writer.get().list.iter().any(|t| Arc::ptr_eq(t, inp)) {
        return false;
    }
    let side = lock(&inp.input_sources);
    let only_source = side.sources.len() == 1;
    if inp.queue.is_some() || !only_source || !inp.local.src.load(Ordering::Relaxed).is_null() {
        return false;
    }
    let current = out.local.home.load(Ordering::Relaxed);
    if current.is_null() {
        // The first local reader: the local value starts as the shared one.
        let (value, _) = out.cell.load();
        // SAFETY: `proof` covers `home`, which the cell joins now; before, no thread
        // touched it (a null home means nobody reads or writes `value`).
        unsafe { out.local.value.with_mut(|p| *p = value) };
        let _ = out.local.keep_home.set(Arc::clone(home));
        out.local.home.store(home_ptr, Ordering::Release);
    } else if current != home_ptr {
        return false;
    }
    // SAFETY: `proof` covers the home of both cells.
    let version = unsafe { out.local.version() };
    let pending = inp.cell.take_changed();
    // SAFETY: as above; the input joins the same home.
    unsafe {
        inp.local.seen.with_mut(|p| {
            *p = Seen {
                from: version,
                seen: version,
                pending,
            }
        })
    };
    lock(&inp.local.keep).push(Arc::clone(out));
    let out_ptr = Arc::as_ptr(out).cast_mut();
    inp.local.src.store(out_ptr, Ordering::Release);
    let both = writer
        .get()
        .list
        .iter()
        .any(|t| t.local.src.load(Ordering::Relaxed) != out_ptr);
    out.local.both.store(both, Ordering::Release);
    home.set_gate(&out.local.gate, !both);
    drop(side);
    true
}

/// Keeps `out`'s shared value and lock-free readers current from now on.
fn share<T: NoUninit + Send + Sync>(proof: &Exclusive<'_>, out: &CopyOutputCore<T>) {
    if !proof.covers(out.local.home.load(Ordering::Relaxed)) {
        return;
    }
    if out.local.both.load(Ordering::Relaxed) {
        return;
    }
    // SAFETY: `proof` covers the cell's home.
    let (value, version) = unsafe { (out.local.value.with(|p| *p), out.local.version()) };
    // Nothing published locally: the shared cell is still current (and still says
    // whether the output ever published).
    if version != 0 {
        out.cell.store(&value, false);
    }
    out.local.both.store(true, Ordering::Release);
    if let Some(home) = out.local.keep_home.get() {
        home.set_gate(&out.local.gate, false);
    }
}

/// Makes `inp` read its own cell again, with the value and changed mark it had, and
/// its output deliver to it on the lock-free path.
fn unlocalize<T: NoUninit + Send + Sync>(proof: &Exclusive<'_>, inp: &CopyInputCore<T>) {
    let src = inp.local.src.load(Ordering::Acquire);
    if src.is_null() {
        return;
    }
    // SAFETY: kept alive by `inp.local.keep`.
    let src = unsafe { &*src };
    if !proof.covers(src.local.home.load(Ordering::Relaxed)) {
        return;
    }
    // SAFETY: `proof` covers the home of both cells.
    let (value, changed) = unsafe {
        let version = src.local.version();
        let seen = inp.local.seen.with(|p| *p);
        let value = if version == seen.from {
            inp.cell.load().0
        } else {
            src.local.value.with(|p| *p)
        };
        (value, seen.pending || seen.seen != version)
    };
    inp.cell.store(&value, changed);
    inp.local.src.store(ptr::null_mut(), Ordering::Release);
    share(proof, src);
}

/// Whether changing the connection `out → inp` must first move either off the local
/// path (called with `out`'s connection lock and `inp`'s sources held).
pub(crate) fn is_local<T: NoUninit + Send + Sync>(
    out: &CopyOutputCore<T>,
    inp: &CopyInputCore<T>,
) -> bool {
    let shared_out =
        out.local.home.load(Ordering::Relaxed).is_null() || out.local.both.load(Ordering::Acquire);
    !shared_out || !inp.local.src.load(Ordering::Acquire).is_null()
}

/// Moves `out` and `inp` off the local path, each on its container's thread at a cycle
/// boundary (see `local.rs`). With `keep`, a change that times out stays queued.
pub(crate) fn leave<T: NoUninit + Send + Sync>(
    out: &Arc<CopyOutputCore<T>>,
    inp: &Arc<CopyInputCore<T>>,
    keep: bool,
) -> Result<(), Busy> {
    if !out.local.both.load(Ordering::Acquire) {
        if let Some(home) = out.local.home() {
            let out = Arc::clone(out);
            home.run(move |proof| share(proof, &out), keep)?;
        }
    }
    let src = inp.local.src.load(Ordering::Acquire);
    if !src.is_null() {
        let src = lock(&inp.local.keep)
            .iter()
            .find(|o| ptr::eq(Arc::as_ptr(o), src))
            .cloned();
        if let Some(home) = src.and_then(|s| s.local.home()) {
            let inp = Arc::clone(inp);
            home.run(move |proof| unlocalize(proof, &inp), keep)?;
        }
    }
    Ok(())
}

/// Makes an existing connection local to `home` if it can be (see [`localize`]), at
/// once when `home`'s container is not running, else at its next cycle boundary.
pub(crate) fn make_local<T: NoUninit + Send + Sync>(
    out: &Arc<CopyOutputCore<T>>,
    inp: &Arc<CopyInputCore<T>>,
    home: &Arc<Home>,
) -> bool {
    let done = Arc::new(AtomicBool::new(false));
    let (o, i, h, d) = (
        Arc::clone(out),
        Arc::clone(inp),
        Arc::clone(home),
        Arc::clone(&done),
    );
    let ran = home.run(
        move |proof| d.store(localize(proof, &h, &o, &i), Ordering::Relaxed),
        false,
    );
    ran.is_ok() && done.load(Ordering::Relaxed)
}
