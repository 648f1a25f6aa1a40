//! Local connections: a connection whose writer and every reader run in one thread
//! container keeps its value in a plain cell that only that container's thread
//! touches. Publishing is a store, reading a load: no CAS, no reference count, no
//! seqlock (issue 18, benchmark B2).
//!
//! The words of this file, in short: a **home** ([`Home`]) is one thread container's
//! set of local connections; a **session** ([`Session`]) is the container thread's
//! hold on its home while it runs cycles (one at a time); a thread's **mark**
//! ([`mark`]) is a number that identifies it (its thread pointer); an output's **gate**
//! is the word a port access compares with the caller's mark — equal means the caller
//! may touch the local cell without atomics.
//!
//! # Who may touch a local cell
//!
//! A thread container owns a [`Home`]. While the container runs cycles, its thread
//! holds a [`Session`] of the home; the session makes the thread the home's owner
//! (the home keeps the thread's [`mark`]) for as long as it lasts, and a home has at
//! most one session at a time. A local cell belongs to one home and is touched only
//!
//! * on the thread that holds the home's session (every port access compares the
//!   calling thread's [`mark`] with the output's gate, which the home keeps equal to
//!   its owner's mark while the output publishes only locally, or else with the home's
//!   owner: one load and a compare, no atomic read-modify-write), or
//! * by an operation holding an [`Exclusive`] proof, which the home hands out only to
//!   code it runs while it has no session (under its mutex, so ordered with the sessions
//!   before and after) or on the session's own thread.
//!
//! A port used from any other thread while its connection is local panics with a
//! message naming it instead of racing (a module's ports belong to its container's
//! thread).
//!
//! # Changing a local connection
//!
//! Anything that changes a local connection — a reader from another container, an
//! inspector probe, a second writer, a disconnect — must happen at a cycle boundary of
//! the owning container, on its thread. Wiring (`wiring.rs`) asks the home to run the
//! change there with [`Home::run`]: done at once when the caller is that thread or the
//! container is not running, otherwise queued, run by the container at its next
//! boundary ([`Session::boundary`], one atomic load per cycle batch) and waited for
//! (at most [`WAIT`]). The change moves the ports back onto the lock-free path: the
//! output then keeps its shared value and its other readers current as well
//! (`both`), an input reads its own cell again. Only the Builder, at start, makes
//! connections local; nothing makes them local again during a run.

use std::marker::PhantomData;
use std::ptr;
use std::time::{Duration, Instant};

use crate::sync::{lock, Arc, AtomicBool, AtomicUsize, Condvar, Mutex, Ordering};

/// How long a change to a local connection waits for the owning container's next
/// cycle boundary before giving up.
pub(crate) const WAIT: Duration = Duration::from_secs(2);

/// The calling thread's mark: a number no other live thread has, never 0.
///
/// On Linux on x86-64 and AArch64 it is the thread pointer, read from its register
/// with one instruction. A `thread_local!` would do as well in a binary, but a module
/// library is compiled as position-independent code, where reaching a thread-local of
/// another crate is a call to `__tls_get_addr` as far as the optimiser knows (the
/// linker relaxes it to two moves later): every register holding a value across the
/// check is then saved to the stack and reloaded, the whole matrix of a b2 stage
/// between its read and its publish. Elsewhere (and under Miri and loom) the mark is
/// the address of a thread-local.
#[inline(always)]
pub(crate) fn mark() -> usize {
    #[cfg(all(target_os = "linux", target_arch = "x86_64", not(miri), not(loom)))]
    {
        let tp: usize;
        // SAFETY: `fs:0` holds the thread pointer itself (the x86-64 TLS ABI, glibc
        // and musl alike); reading it has no side effect.
        unsafe {
            std::arch::asm!("mov {}, qword ptr fs:[0]", out(reg) tp,
                options(nostack, readonly, pure, preserves_flags));
        }
        tp
    }
    #[cfg(all(target_os = "linux", target_arch = "aarch64", not(miri), not(loom)))]
    {
        let tp: usize;
        // SAFETY: reads the thread pointer register; no side effect.
        unsafe {
            std::arch::asm!("mrs {}, tpidr_el0", out(reg) tp,
                options(nostack, nomem, pure, preserves_flags));
        }
        tp
    }
    #[cfg(not(all(
        target_os = "linux",
        any(target_arch = "x86_64", target_arch = "aarch64"),
        not(miri),
        not(loom)
    )))]
    {
        MARK.with(|m| ptr::from_ref(m) as usize)
    }
}

#[cfg(all(
    not(loom),
    not(all(
        target_os = "linux",
        any(target_arch = "x86_64", target_arch = "aarch64"),
        not(miri)
    ))
))]
std::thread_local! {
    /// Its address is the thread's mark where the thread pointer is not used.
    static MARK: u8 = const { 0 };
}

#[cfg(loom)]
loom::thread_local! {
    static MARK: u8 = 0;
}

/// A registered gate (see [`Home::set_gate`]).
struct Gate(*const AtomicUsize);

// SAFETY: points to an atomic inside an output that outlives its registration; only
// used for atomic stores.
unsafe impl Send for Gate {}

type Op = Box<dyn FnOnce(&Exclusive<'_>) + Send>;

/// A change waiting for the session's next boundary.
struct Queued {
    ticket: u64,
    op: Op,
    /// Someone waits for it (else its ticket is not reported done).
    waited: bool,
}

struct State {
    /// A thread holds a session.
    session: bool,
    queue: Vec<Queued>,
    /// Tickets handed out so far.
    issued: u64,
    /// Tickets done whose waiters have not seen it yet.
    done: Vec<u64>,
}

/// The owner of a thread container's local connections (see the module docs).
pub struct Home {
    /// The [`mark`] of the thread holding the session; 0: none. Written under `state`'s
    /// mutex; read without it by the port checks, where only the owning thread can find
    /// its own mark (a thread only ever stores its own mark or 0 here, so a stale value
    /// another thread sees is never that thread's mark).
    owner: AtomicUsize,
    /// The gates of its local outputs that take the fast path (`copy_local.rs`): each
    /// holds `owner` while the output publishes only locally, so a publish compares one
    /// word of its own with the caller's mark. Set with `owner`, under `state`'s mutex
    /// (lock order: `state`, then `gates`), and by [`Home::set_gate`].
    gates: Mutex<Vec<Gate>>,
    /// Set when `queue` is not empty: the session's boundary check is this one load.
    pending: AtomicBool,
    state: Mutex<State>,
    served: Condvar,
}

/// Proof that the holder may touch the local cells of one home: it is the session's
/// thread, or the home has no session and the holder has its mutex.
pub(crate) struct Exclusive<'a> {
    home: &'a Home,
}

impl Exclusive<'_> {
    /// Is `home` the home this proof is for?
    pub(crate) fn covers(&self, home: *const Home) -> bool {
        ptr::eq(self.home, home)
    }
}

/// A thread running a home's container (see [`Home::enter`]). Neither `Send` nor
/// `Sync`: it makes the thread that created it the home's owner. A leaked session
/// leaves that thread the owner for good; a thread started after it ended may get the
/// same mark (its thread block reused), but then the two never run at once, and the
/// reuse itself orders them (the C library hands a thread block on only after its
/// thread is gone), so the home's cells still have one thread at a time.
pub struct Session {
    home: Arc<Home>,
    /// False for a nested session of the same home, which changes nothing (sessions
    /// of different homes nest as well: each home has its own owner).
    outer: bool,
    _not_send: PhantomData<*const ()>,
}

/// A change to a local connection did not reach the owning container in time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Busy;

impl Default for Home {
    fn default() -> Self {
        Self::new()
    }
}

impl Home {
    /// A home without a session.
    pub fn new() -> Self {
        Home {
            owner: AtomicUsize::new(0),
            gates: Mutex::new(Vec::new()),
            pending: AtomicBool::new(false),
            state: Mutex::new(State {
                session: false,
                queue: Vec::new(),
                issued: 0,
                done: Vec::new(),
            }),
            served: Condvar::new(),
        }
    }

    /// Starts running the home's container on this thread: from now until the session
    /// is dropped, this thread may touch the home's local cells. Entering again on the
    /// same thread nests harmlessly.
    ///
    /// # Panics
    /// If another thread holds a session of this home (a container's cycles run on one
    /// thread at a time).
    ///
    /// An associated function rather than a method: under loom, `Arc` is loom's, which
    /// cannot be a method receiver.
    pub fn enter(home: &Arc<Home>) -> Session {
        if home.is_owner() {
            return Session {
                home: Arc::clone(home),
                outer: false,
                _not_send: PhantomData,
            };
        }
        let mut state = lock(&home.state);
        assert!(
            !state.session,
            "a thread container's cycles run on one thread at a time"
        );
        state.session = true;
        let me = mark();
        home.owner.store(me, Ordering::Relaxed);
        home.open_gates(me);
        home.serve(&mut state);
        drop(state);
        Session {
            home: Arc::clone(home),
            outer: true,
            _not_send: PhantomData,
        }
    }

    /// Does the calling thread hold this home's session? One load and a compare: the
    /// check an access to a local cell makes when the output's gate is shut.
    #[inline(always)]
    pub(crate) fn is_owner(&self) -> bool {
        self.owner.load(Ordering::Relaxed) == mark()
    }

    /// Stores `owner` in every registered gate (the caller holds `state`'s mutex and is
    /// the thread `owner` names, or `owner` is 0).
    fn open_gates(&self, owner: usize) {
        for gate in lock(&self.gates).iter() {
            // SAFETY: a gate is removed before its output is freed (`set_gate`).
            unsafe { (*gate.0).store(owner, Ordering::Relaxed) };
        }
    }

    /// Registers `gate` (`open`) or removes it: an open gate holds the session thread's
    /// mark from now on, a closed one 0. The caller holds an [`Exclusive`] proof of this
    /// home (so `owner` is the caller's own mark or 0), or is dropping the gate's output
    /// (`open` false). The gate must stay where it is until it is removed.
    pub(crate) fn set_gate(&self, gate: &AtomicUsize, open: bool) {
        let mut gates = lock(&self.gates);
        gates.retain(|g| !ptr::eq(g.0, gate));
        if open {
            gates.push(Gate(gate));
            gate.store(self.owner.load(Ordering::Relaxed), Ordering::Relaxed);
        } else {
            gate.store(0, Ordering::Relaxed);
        }
    }

    /// Runs the queued changes (the caller holds the session or the mutex with no
    /// session) and wakes their waiters.
    fn serve(&self, state: &mut State) {
        if state.queue.is_empty() {
            return;
        }
        self.pending.store(false, Ordering::Relaxed);
        let proof = Exclusive { home: self };
        for queued in std::mem::take(&mut state.queue) {
            (queued.op)(&proof);
            if queued.waited {
                state.done.push(queued.ticket);
            }
        }
        self.served.notify_all();
    }

    /// Runs `op` where it may touch this home's local cells: at once if the caller
    /// holds the session or the container is not running, else at the container's next
    /// cycle boundary, waiting for it at most [`WAIT`]. On `Busy`, `keep` leaves the
    /// change queued for that boundary; otherwise it is withdrawn.
    pub(crate) fn run(
        &self,
        op: impl FnOnce(&Exclusive<'_>) + Send + 'static,
        keep: bool,
    ) -> Result<(), Busy> {
        if self.is_owner() {
            op(&Exclusive { home: self });
            return Ok(());
        }
        let mut state = lock(&self.state);
        if !state.session {
            op(&Exclusive { home: self });
            return Ok(());
        }
        state.issued += 1;
        let ticket = state.issued;
        state.queue.push(Queued {
            ticket,
            op: Box::new(op),
            waited: true,
        });
        self.pending.store(true, Ordering::Release);
        let deadline = Instant::now() + WAIT;
        loop {
            if let Some(at) = state.done.iter().position(|t| *t == ticket) {
                state.done.swap_remove(at);
                return Ok(());
            }
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                if keep {
                    for queued in &mut state.queue {
                        if queued.ticket == ticket {
                            queued.waited = false;
                        }
                    }
                } else {
                    state.queue.retain(|q| q.ticket != ticket);
                }
                return Err(Busy);
            }
            state = match self.served.wait_timeout(state, left) {
                Ok((guard, _)) => guard,
                Err(poisoned) => poisoned.into_inner().0,
            };
        }
    }
}

impl Session {
    /// A cycle boundary: runs the changes other threads queued. One atomic load when
    /// there are none.
    #[inline]
    pub fn boundary(&self) {
        if self.home.pending.load(Ordering::Acquire) {
            let mut state = lock(&self.home.state);
            self.home.serve(&mut state);
        }
    }
}

impl Drop for Session {
    fn drop(&mut self) {
        if !self.outer {
            return;
        }
        let mut state = lock(&self.home.state);
        self.home.serve(&mut state);
        state.session = false;
        // Unowned before the mutex is released: from then on other threads may run
        // changes themselves.
        self.home.open_gates(0);
        self.home.owner.store(0, Ordering::Relaxed);
        drop(state);
    }
}

impl std::fmt::Debug for Home {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Home")
    }
}

/// Panics for a port used outside its container's thread while its connection is
/// local (see the module docs).
///
/// It takes the name as `&String`, not `&str`: the port paths then pass one pointer and
/// read the name's address and length only here, off the path every publish and read
/// takes (with `&str` the compiler loaded both at the top of every module step).
#[cold]
#[inline(never)]
#[allow(clippy::ptr_arg)]
pub(crate) fn foreign_access(port: &String) -> ! {
    panic!(
        "the port `{port}` is connected inside its thread container and was used from \
         another thread; a module's ports may only be used by the thread that runs it"
    )
}
