//! [`ServicePort`]: the serving side, its request queue and its handler.
//!
//! Locks, and their one order: a client's state, then the server's state (see
//! `client.rs`). Nothing here holds a lock while running user code — handlers,
//! notifiers, or the drop of a withdrawn request (which answers its caller and may
//! run that caller's notifier) — so a handler may call any service, its own included,
//! without deadlocking on ferroc's locks. (A *blocking* call from a handler to its own
//! server-executed service still waits for itself; that is the model's self-call
//! deadlock, which the compiler's checks report.)

use std::collections::VecDeque;
use std::fmt;
use std::panic::{catch_unwind, resume_unwind, AssertUnwindSafe};

use super::client::ClientCore;
use super::reply::{Responder, Slot};
use super::{CallError, Executes};
use crate::port::Notifier;
use crate::sync::{lock, Arc, AtomicBool, Mutex, Ordering};

/// A request waiting in a server's queue.
pub(crate) struct Queued<Req, Resp> {
    /// The calling client (its core's address), to withdraw its requests when it is
    /// disconnected. Unique among connected clients: a core lives while connected.
    client: usize,
    request: Req,
    reply: Responder<Resp>,
}

/// Where the handler lives.
enum Exec<Req, Resp> {
    /// `executes="server"`: requests wait in a bounded queue for the server's step.
    Server { capacity: usize },
    /// `executes="caller"`: the handler, run by each caller on its own thread.
    Caller(Box<dyn Fn(Req) -> Resp + Send + Sync>),
}

pub(crate) struct ServerState<Req, Resp> {
    /// False once the port is dropped: nothing is accepted any more.
    open: bool,
    queue: VecDeque<Queued<Req, Resp>>,
    pub(crate) clients: Vec<Arc<ClientCore<Req, Resp>>>,
    notifier: Option<Notifier>,
}

pub(crate) struct ServerCore<Req, Resp> {
    pub(crate) name: String,
    exec: Exec<Req, Resp>,
    /// A handler panicked: the service is stopped. Written under `state` (so queueing
    /// and stopping are ordered), read without it by inline calls.
    stopped: AtomicBool,
    pub(crate) state: Mutex<ServerState<Req, Resp>>,
}

impl<Req, Resp> ServerCore<Req, Resp> {
    /// See [`ServicePort::set_notifier`].
    pub(crate) fn set_notifier(&self, notifier: Notifier) -> Result<(), Notifier> {
        let mut state = lock(&self.state);
        if state.notifier.is_some() {
            return Err(notifier);
        }
        state.notifier = Some(notifier);
        Ok(())
    }

    /// Queues a request (server-executed services), under the caller's client lock so
    /// that a concurrent disconnect either withdraws it or comes first. Returns the
    /// reply slot and the server's notifier, to call once every lock is released.
    pub(crate) fn enqueue(
        &self,
        client: usize,
        request: Req,
        reply_notifier: Option<Notifier>,
    ) -> Result<(Arc<Slot<Resp>>, Option<Notifier>), CallError> {
        let Exec::Server { capacity } = self.exec else {
            unreachable!("enqueue is only called for server-executed services")
        };
        let mut state = lock(&self.state);
        if !state.open {
            return Err(CallError::NotConnected);
        }
        if self.stopped.load(Ordering::Relaxed) {
            return Err(CallError::ServerPanicked);
        }
        if state.queue.len() >= capacity {
            return Err(CallError::QueueFull);
        }
        let slot = Slot::new(reply_notifier);
        state.queue.push_back(Queued {
            client,
            request,
            reply: Responder::new(Arc::clone(&slot)),
        });
        Ok((slot, state.notifier.clone()))
    }

    pub(crate) fn is_inline(&self) -> bool {
        matches!(self.exec, Exec::Caller(_))
    }

    /// Runs the handler of a caller-executed service on the calling thread.
    pub(crate) fn call_inline(&self, request: Req) -> Result<Resp, CallError> {
        let Exec::Caller(handler) = &self.exec else {
            unreachable!("call_inline is only called for caller-executed services")
        };
        if self.stopped.load(Ordering::Acquire) {
            return Err(CallError::ServerPanicked);
        }
        catch_unwind(AssertUnwindSafe(|| handler(request))).map_err(|_payload| {
            // The panic hook has already printed the message; the caller gets the error.
            self.stop();
            CallError::ServerPanicked
        })
    }

    /// Removes the queued requests of one client (it is being disconnected). The
    /// caller drops them once its locks are released; each answers `Disconnected`.
    pub(crate) fn withdraw(
        state: &mut ServerState<Req, Resp>,
        client: usize,
    ) -> Vec<Queued<Req, Resp>> {
        let mut withdrawn = Vec::new();
        let mut kept = VecDeque::with_capacity(state.queue.len());
        for q in state.queue.drain(..) {
            if q.client == client {
                withdrawn.push(q);
            } else {
                kept.push_back(q);
            }
        }
        state.queue = kept;
        withdrawn
    }

    fn pop(&self) -> Option<Queued<Req, Resp>> {
        lock(&self.state).queue.pop_front()
    }

    /// A handler panicked: answer everything queued with `ServerPanicked` and refuse
    /// every later call, like a thread container stops a panicking step.
    fn stop(&self) {
        let drained: Vec<_> = {
            let mut state = lock(&self.state);
            self.stopped.store(true, Ordering::Release);
            state.queue.drain(..).collect()
        };
        for q in drained {
            q.reply.fail(CallError::ServerPanicked);
        }
    }

    /// Disconnects every client; their queued requests answer `Disconnected`.
    pub(crate) fn disconnect_all(&self) {
        let clients = std::mem::take(&mut lock(&self.state).clients);
        let mut withdrawn = Vec::new();
        for client in clients {
            let mut c = lock(&client.state);
            if c.service.as_ref().is_some_and(|s| std::ptr::eq(&**s, self)) {
                withdrawn.extend(ClientCore::unlink(&client, &mut c));
            }
        }
        drop(withdrawn);
    }
}

/// The serving side of a service: owned by the module that implements it.
///
/// How a request is executed is fixed when the port is created (the model's
/// `<service executes=…>`):
///
/// * [`new`](Self::new) / [`with_capacity`](Self::with_capacity) — `executes="server"`
///   (the default): calls wait in a bounded queue until the serving module's step
///   takes them with [`serve_pending`](Self::serve_pending),
///   [`serve_one`](Self::serve_one) or [`take_request`](Self::take_request). The
///   handler therefore runs on the server's thread container, with `&mut` access to
///   the module's state and no locking. Register the container's
///   [`Wakeup`](crate::port::Wakeup) with [`set_notifier`](Self::set_notifier) to run a
///   data-triggered container when a request arrives.
/// * [`executed_by_caller`](Self::executed_by_caller) — `executes="caller"`: there is
///   no queue; each caller runs the handler inline on its own thread.
///
/// **Full queue.** A call that finds the queue full fails at once with
/// [`CallError::QueueFull`], for blocking and asynchronous calls alike. The caller
/// decides whether to retry; waiting for room would be a second, hidden wait (and an
/// asynchronous call must never wait). Queued requests are never dropped to make room.
///
/// **Panics.** If a handler panics, the call it was serving and every queued call fail
/// with [`CallError::ServerPanicked`], and so does every later call: the service is
/// stopped for good ([`is_stopped`](Self::is_stopped)), as a thread container stops a
/// step that panicked — the module's state may be half-updated. `serve_*` then
/// re-raise the panic so the container reports it against the step.
///
/// **Drop.** Dropping the port disconnects its clients; calls still queued fail with
/// [`CallError::Disconnected`], later calls with [`CallError::NotConnected`]. A call
/// a handler is already executing is answered normally.
pub struct ServicePort<Req, Resp> {
    pub(crate) core: Arc<ServerCore<Req, Resp>>,
}

impl<Req: Send + 'static, Resp: Send + 'static> ServicePort<Req, Resp> {
    /// Queue capacity of [`new`](Self::new).
    pub const DEFAULT_CAPACITY: usize = 16;

    /// A service executed by the serving module's thread container, with a queue of
    /// [`DEFAULT_CAPACITY`](Self::DEFAULT_CAPACITY) requests.
    pub fn new(name: impl Into<String>) -> Self {
        Self::with_capacity(name, Self::DEFAULT_CAPACITY)
    }

    /// A service executed by the serving module's thread container, queueing at most
    /// `capacity` requests (raised to 1 if 0).
    pub fn with_capacity(name: impl Into<String>, capacity: usize) -> Self {
        Self::build(
            name.into(),
            Exec::Server {
                capacity: capacity.max(1),
            },
        )
    }

    /// A service executed inline by its callers (`executes="caller"`).
    ///
    /// The handler runs on each caller's thread, possibly on several at once and at the
    /// same time as the serving module's own step: hence `Fn + Send + Sync`. State it
    /// shares with the module must be behind a `Mutex`, `RwLock` or atomics (put them in
    /// an `Arc` the module keeps too); the compiler enforces this. The handler runs
    /// while the caller holds whatever locks it holds — the deadlock analysis counts
    /// the handler's locks as taken by the caller — and a timeout does not interrupt
    /// it: an inline call is a function call.
    pub fn executed_by_caller(
        name: impl Into<String>,
        handler: impl Fn(Req) -> Resp + Send + Sync + 'static,
    ) -> Self {
        Self::build(name.into(), Exec::Caller(Box::new(handler)))
    }

    fn build(name: String, exec: Exec<Req, Resp>) -> Self {
        ServicePort {
            core: Arc::new(ServerCore {
                name,
                exec,
                stopped: AtomicBool::new(false),
                state: Mutex::new(ServerState {
                    open: true,
                    queue: VecDeque::new(),
                    clients: Vec::new(),
                    notifier: None,
                }),
            }),
        }
    }

    /// The port's name.
    pub fn name(&self) -> &str {
        &self.core.name
    }

    /// Who executes requests.
    pub fn executes(&self) -> Executes {
        match self.core.exec {
            Exec::Server { .. } => Executes::Server,
            Exec::Caller(_) => Executes::Caller,
        }
    }

    /// The queue's capacity (`None` for a caller-executed service, which has none).
    pub fn capacity(&self) -> Option<usize> {
        match self.core.exec {
            Exec::Server { capacity } => Some(capacity),
            Exec::Caller(_) => None,
        }
    }

    /// Number of requests waiting to be served.
    pub fn pending_len(&self) -> usize {
        lock(&self.core.state).queue.len()
    }

    /// Number of connected clients.
    pub fn client_count(&self) -> usize {
        lock(&self.core.state).clients.len()
    }

    /// Whether a handler panicked, which stops the service (see the type's docs).
    pub fn is_stopped(&self) -> bool {
        self.core.stopped.load(Ordering::Acquire)
    }

    /// Registers the notifier every accepted request calls (once per port; a thread
    /// container registers its wakeup). Gives it back if one is already set. Called on
    /// the caller's thread after the request is queued: keep it short.
    pub fn set_notifier(&self, notifier: Notifier) -> Result<(), Notifier> {
        self.core.set_notifier(notifier)
    }

    /// A type-erased handle for wiring by name (the runtime builder's use).
    pub fn handle(&self) -> super::ServiceHandle {
        super::ServiceHandle::new(&self.core, self.executes())
    }

    /// Serves the requests that are queued now, in arrival order, each with `handler`;
    /// returns how many. Requests arriving meanwhile (a handler may even call its own
    /// service asynchronously) wait for the next call, so one step does bounded work.
    /// Call it from the serving module's step. Re-raises a handler's panic (see the
    /// type's docs).
    pub fn serve_pending(&self, mut handler: impl FnMut(Req) -> Resp) -> usize {
        let queued = self.pending_len();
        let mut served = 0;
        while served < queued && self.serve_one(&mut handler) {
            served += 1;
        }
        served
    }

    /// Serves the oldest queued request, if any, with `handler`; false if none was
    /// queued. Re-raises a handler's panic (see the type's docs).
    pub fn serve_one(&self, handler: impl FnOnce(Req) -> Resp) -> bool {
        let Some(q) = self.core.pop() else {
            return false;
        };
        let Queued { request, reply, .. } = q;
        match catch_unwind(AssertUnwindSafe(|| handler(request))) {
            Ok(response) => reply.respond(response),
            Err(payload) => {
                reply.fail(CallError::ServerPanicked);
                self.core.stop();
                resume_unwind(payload);
            }
        }
        true
    }

    /// Takes the oldest queued request to answer later, possibly from another thread
    /// or in a later cycle (see [`Request`]).
    pub fn take_request(&self) -> Option<Request<Req, Resp>> {
        let Queued { request, reply, .. } = self.core.pop()?;
        let core = Arc::clone(&self.core);
        let reply = reply.handed_out(Box::new(move || core.stop()));
        Some(Request { request, reply })
    }

    /// Disconnects every client. Their queued requests fail with
    /// [`CallError::Disconnected`]; requests already taken are answered normally.
    pub fn disconnect_all(&self) {
        self.core.disconnect_all();
    }
}

impl<Req, Resp> Drop for ServicePort<Req, Resp> {
    fn drop(&mut self) {
        // Close first, so that nothing is queued behind the disconnects; then answer
        // whatever is left (nothing, unless a client raced its own disconnect).
        lock(&self.core.state).open = false;
        self.core.disconnect_all();
        let left: Vec<_> = lock(&self.core.state).queue.drain(..).collect();
        drop(left);
    }
}

impl<Req, Resp> fmt::Debug for ServicePort<Req, Resp> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("ServicePort")
            .field("name", &self.core.name)
            .finish_non_exhaustive()
    }
}

/// A request taken with [`ServicePort::take_request`], to answer when the answer is
/// ready.
///
/// If it is dropped unanswered, the caller gets [`CallError::Disconnected`]; if it is
/// dropped by a panic, the caller gets [`CallError::ServerPanicked`] and the service is
/// stopped, as when a `serve_*` handler panics.
pub struct Request<Req, Resp> {
    request: Req,
    reply: Responder<Resp>,
}

impl<Req, Resp> Request<Req, Resp> {
    /// The request.
    pub fn request(&self) -> &Req {
        &self.request
    }

    /// Answers the call.
    pub fn respond(self, response: Resp) {
        self.reply.respond(response);
    }

    /// The request by value, and the [`Responder`] that answers it.
    pub fn into_parts(self) -> (Req, Responder<Resp>) {
        (self.request, self.reply)
    }
}

impl<Req: fmt::Debug, Resp> fmt::Debug for Request<Req, Resp> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Request")
            .field("request", &self.request)
            .finish_non_exhaustive()
    }
}
