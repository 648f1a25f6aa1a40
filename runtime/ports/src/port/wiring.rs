//! Connecting and disconnecting outputs and inputs (n:m), shared by both port kinds.
//!
//! Each output has a [`Fanout`]: the copy-on-write list of its inputs, read by publishers
//! through a [`Snapshot`]. Each input has [`InputSources`]: its sources and whatever it must
//! keep alive for them (the buffer pools of refcounted outputs). Connection changes lock
//! the output's snapshot writer first, then the input's sources — always in that order —
//! and never run user code (notifiers) while holding either.

use std::fmt;

use super::local::Busy;
use super::snapshot::Snapshot;
use crate::sync::{fence, lock, Arc, AtomicUsize, Mutex, Ordering};

/// Options for [`connect`](super::connect).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct ConnectOptions {
    /// Push the output's current value to the input at once, if the output has
    /// published before and this is the input's only source (FINROC's rule: no initial
    /// push into an input with several sources, none into a queue). Default: true.
    pub initial_push: bool,
    /// The writer and the reader run in one thread container (the compiler's plan
    /// marks such connections): the `Builder` (`ferroc_app`) then makes the
    /// connection local at start (`port/local.rs`), and refuses to start if they do
    /// not. Ports connected directly ignore it. Default: false.
    pub local: bool,
}

impl Default for ConnectOptions {
    fn default() -> Self {
        ConnectOptions {
            initial_push: true,
            local: false,
        }
    }
}

impl ConnectOptions {
    /// These options with `initial_push` set as given.
    pub fn with_initial_push(mut self, initial_push: bool) -> Self {
        self.initial_push = initial_push;
        self
    }

    /// These options with `local` set as given.
    pub fn with_local(mut self, local: bool) -> Self {
        self.local = local;
        self
    }
}

/// Why a connection was not made.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum ConnectError {
    /// The two ports are already connected (nothing changed).
    AlreadyConnected {
        /// Name of the output port.
        output: String,
        /// Name of the input port.
        input: String,
    },
    /// The ports carry different value types (or different port kinds): only
    /// possible when wiring through type-erased handles.
    TypeMismatch {
        /// Name and value type of the output port.
        output: String,
        /// Name and value type of the input port.
        input: String,
    },
    /// The connection would change a connection local to a running thread container,
    /// which did not reach a cycle boundary in time to apply the change.
    Busy {
        /// Name of the output port.
        output: String,
        /// Name of the input port.
        input: String,
    },
}

impl fmt::Display for ConnectError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ConnectError::AlreadyConnected { output, input } => {
                write!(f, "`{output}` is already connected to `{input}`")
            }
            ConnectError::TypeMismatch { output, input } => {
                write!(
                    f,
                    "cannot connect `{output}` to `{input}`: the value types differ"
                )
            }
            ConnectError::Busy { output, input } => write!(
                f,
                "cannot connect `{output}` to `{input}` now: a connection of theirs runs \
                 inside a thread container that did not reach a cycle boundary within {} s \
                 (it may be stuck in a step); try again",
                super::local::WAIT.as_secs()
            ),
        }
    }
}

impl std::error::Error for ConnectError {}

/// The inputs an output delivers to.
pub(crate) struct Targets<I> {
    pub(crate) list: Vec<Arc<I>>,
    /// Buffer references one publish hands out to `list` (refcounted ports).
    pub(crate) refs: usize,
}

/// An output's side of its connections.
pub(crate) struct Fanout<I> {
    pub(crate) snap: Snapshot<Targets<I>>,
    /// `refs` of the current targets, readable before loading the snapshot.
    pub(crate) refs_hint: AtomicUsize,
}

impl<I> Fanout<I> {
    pub(crate) fn new() -> Self {
        Fanout {
            snap: Snapshot::new(Targets {
                list: Vec::new(),
                refs: 0,
            }),
            refs_hint: AtomicUsize::new(0),
        }
    }

    pub(crate) fn len(&self) -> usize {
        self.snap.read().load().list.len()
    }
}

/// An input's side of its connections.
pub(crate) struct InputSources<O, R> {
    pub(crate) sources: Vec<Arc<O>>,
    /// Kept alive for the sources, past disconnection (see `pool.rs`).
    pub(crate) retained: R,
}

pub(crate) trait OutCore: Send + Sync + Sized + 'static {
    type In: InCore<Out = Self>;
    fn name(&self) -> &str;
    fn fanout(&self) -> &Fanout<Self::In>;
    /// Called with both sides locked, before the input can receive anything from us.
    fn retain(&self, retained: &mut <Self::In as InCore>::Retained);
    /// Delivers the current value unless the input changed since `mark` was taken.
    fn initial_push(&self, input: &Self::In, mark: <Self::In as InCore>::Mark);
    /// Whether the connection to `input` cannot change before `leave_local` moved
    /// either end off the local path (`local.rs`). Called with both sides locked.
    fn is_local(&self, _input: &Self::In) -> bool {
        false
    }
    /// Moves both ends off the local path, each on its container's thread at a cycle
    /// boundary; called with no lock held. With `keep`, a change that times out stays
    /// queued for that boundary.
    fn leave_local(_out: &Arc<Self>, _input: &Arc<Self::In>, _keep: bool) -> Result<(), Busy> {
        Ok(())
    }
    /// What makes the connection local to a home later (`None`: this port kind has no
    /// local path).
    fn local_pair(_out: &Arc<Self>, _input: &Arc<Self::In>) -> Option<LocalPair> {
        None
    }
}

/// Makes one connection local to a thread container's home; true if it became local.
#[doc(hidden)]
pub type LocalPair = Box<dyn Fn(&Arc<super::Home>) -> bool + Send + Sync>;

pub(crate) trait InCore: Send + Sync + Sized + 'static {
    type Out: OutCore<In = Self>;
    type Retained: Send;
    type Mark;
    fn name(&self) -> &str;
    fn input_sources(&self) -> &Mutex<InputSources<Self::Out, Self::Retained>>;
    /// Buffer references one delivery to this input consumes.
    fn refs_per_delivery(&self) -> usize;
    fn is_queued(&self) -> bool;
    fn mark(&self) -> Self::Mark;
    /// A source went away: publishers blocked on our full queue must re-check.
    fn wake_producers(&self);
}

/// Is `out` (still) a source of `inp`? Used by publishers blocked on a full queue.
pub(crate) fn is_source<I: InCore>(inp: &I, out: &I::Out) -> bool {
    lock(inp.input_sources())
        .sources
        .iter()
        .any(|s| std::ptr::eq(Arc::as_ptr(s), out))
}

pub(crate) fn connect<O: OutCore>(
    out: &Arc<O>,
    inp: &Arc<O::In>,
    opts: ConnectOptions,
) -> Result<(), ConnectError> {
    let (mut writer, mut side) = loop {
        let writer = out.fanout().snap.write();
        if writer.get().list.iter().any(|t| Arc::ptr_eq(t, inp)) {
            return Err(ConnectError::AlreadyConnected {
                output: out.name().to_owned(),
                input: inp.name().to_owned(),
            });
        }
        let side = lock(inp.input_sources());
        if !out.is_local(inp) {
            break (writer, side);
        }
        // A local end changes only on its container's thread: have it moved to the
        // lock-free path there, then look again (nothing makes it local again).
        drop(side);
        drop(writer);
        O::leave_local(out, inp, false).map_err(|Busy| ConnectError::Busy {
            output: out.name().to_owned(),
            input: inp.name().to_owned(),
        })?;
    };
    let current = writer.get();
    out.retain(&mut side.retained);
    let only_source = side.sources.is_empty();
    side.sources.push(Arc::clone(out));
    // Taken before the input becomes visible to our publishers: anything delivered
    // after this point wins over the initial push.
    let mark = inp.mark();
    let mut list = current.list.clone();
    list.push(Arc::clone(inp));
    let refs = current.refs + inp.refs_per_delivery();
    out.fanout().refs_hint.store(refs, Ordering::Relaxed);
    writer.replace(Targets { list, refs });
    drop(side);
    drop(writer);
    if opts.initial_push && only_source && !inp.is_queued() {
        // Publish swaps the output's value in, then registers as a reader of the list
        // (an RMW of the reader count) and loads it; `replace` swapped the list and
        // then did an RMW of the same count. Whichever RMW came second synchronises
        // with the first, so either that publish sees the new list or we now see its
        // value: a value published concurrently is never missed. (The fence adds the
        // same guarantee through SeqCst for good measure.)
        fence(Ordering::SeqCst);
        out.initial_push(inp, mark);
    }
    Ok(())
}

/// Removes the connection; false if there was none. Publishes already under way may
/// still deliver to the input once (they read the list before the change).
pub(crate) fn disconnect<O: OutCore>(out: &Arc<O>, inp: &Arc<O::In>) -> bool {
    let (mut writer, mut side) = loop {
        let writer = out.fanout().snap.write();
        if !writer.get().list.iter().any(|t| Arc::ptr_eq(t, inp)) {
            return false;
        }
        let side = lock(inp.input_sources());
        if !out.is_local(inp) {
            break (writer, side);
        }
        drop(side);
        drop(writer);
        // A container that does not reach a boundary in time applies the change at its
        // next one: until then its input still sees the output's values, as a publish
        // under way may deliver once after a disconnect.
        if O::leave_local(out, inp, true).is_err() {
            let writer = out.fanout().snap.write();
            if !writer.get().list.iter().any(|t| Arc::ptr_eq(t, inp)) {
                return false;
            }
            let side = lock(inp.input_sources());
            break (writer, side);
        }
    };
    let current = writer.get();
    side.sources.retain(|s| !Arc::ptr_eq(s, out));
    let list: Vec<_> = current
        .list
        .iter()
        .filter(|t| !Arc::ptr_eq(t, inp))
        .cloned()
        .collect();
    let refs = current.refs - inp.refs_per_delivery();
    out.fanout().refs_hint.store(refs, Ordering::Relaxed);
    writer.replace(Targets { list, refs });
    drop(side);
    drop(writer);
    inp.wake_producers();
    true
}

pub(crate) fn disconnect_all_targets<O: OutCore>(out: &Arc<O>) {
    let targets: Vec<_> = out.fanout().snap.write().get().list.clone();
    for t in &targets {
        disconnect(out, t);
    }
}

pub(crate) fn disconnect_all_sources<I: InCore>(inp: &Arc<I>) {
    let sources: Vec<_> = lock(inp.input_sources()).sources.clone();
    for s in &sources {
        disconnect(s, inp);
    }
}
