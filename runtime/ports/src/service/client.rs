//! [`ClientPort`]: the calling side, and connecting it to a service.
//!
//! A client's state (which service it is connected to, its notifier) sits behind one
//! mutex. Calls to a server-executed service queue their request while holding it, and
//! connect/disconnect hold it while they change the link: so a request is either queued
//! before a disconnect (and withdrawn by it) or sent after it (and finds no service).
//! The lock order is always client, then server.

use std::fmt;
use std::time::{Duration, Instant};

use super::reply::{PendingResponse, Slot};
use super::server::{Queued, ServerCore};
use super::{CallError, ServiceConnectError, ServicePort};
use crate::port::Notifier;
use crate::sync::{lock, Arc, Mutex};

pub(crate) struct ClientState<Req, Resp> {
    pub(crate) service: Option<Arc<ServerCore<Req, Resp>>>,
    notifier: Option<Notifier>,
}

pub(crate) struct ClientCore<Req, Resp> {
    name: String,
    pub(crate) state: Mutex<ClientState<Req, Resp>>,
}

impl<Req, Resp> ClientCore<Req, Resp> {
    /// See [`ClientPort::set_notifier`].
    pub(crate) fn set_notifier(&self, notifier: Notifier) -> Result<(), Notifier> {
        let mut state = lock(&self.state);
        if state.notifier.is_some() {
            return Err(notifier);
        }
        state.notifier = Some(notifier);
        Ok(())
    }

    pub(crate) fn name(&self) -> &str {
        &self.name
    }

    /// The identity a server files this client's requests under.
    fn id(this: &Arc<Self>) -> usize {
        Arc::as_ptr(this).cast::<()>() as usize
    }

    /// Cuts the link held in `state` (the client's locked state). The requests the
    /// client still has queued are withdrawn and returned: drop them after releasing
    /// the lock (each then answers its caller with `Disconnected`).
    pub(crate) fn unlink(
        this: &Arc<Self>,
        state: &mut ClientState<Req, Resp>,
    ) -> Vec<Queued<Req, Resp>> {
        let Some(service) = state.service.take() else {
            return Vec::new();
        };
        let mut s = lock(&service.state);
        s.clients.retain(|c| !Arc::ptr_eq(c, this));
        ServerCore::withdraw(&mut s, Self::id(this))
    }
}

/// The calling side of a service: owned by the module that calls it.
///
/// Connected to at most one [`ServicePort`] at a time (with [`connect`](super::connect));
/// every call goes to that service. A call never hangs on a missing or vanished
/// server: unconnected → [`CallError::NotConnected`]; service dropped or client
/// disconnected while the request waits in the queue → [`CallError::Disconnected`].
///
/// What a call *can* wait for without limit is a live server that does not serve —
/// its container stopped, or it is the caller's own thread container (a module calling
/// a service of its own container synchronously waits for itself). Give such calls a
/// timeout ([`with_timeout`](Self::with_timeout), the model's `<client timeout>`, or
/// [`call_timeout`](Self::call_timeout)), or call asynchronously.
pub struct ClientPort<Req, Resp> {
    core: Arc<ClientCore<Req, Resp>>,
    timeout: Option<Duration>,
}

enum Submitted<Resp> {
    Queued(Arc<Slot<Resp>>),
    Done(Resp),
}

impl<Req: Send + 'static, Resp: Send + 'static> ClientPort<Req, Resp> {
    /// An unconnected client whose [`call`](Self::call) waits without a time limit.
    pub fn new(name: impl Into<String>) -> Self {
        ClientPort {
            core: Arc::new(ClientCore {
                name: name.into(),
                state: Mutex::new(ClientState {
                    service: None,
                    notifier: None,
                }),
            }),
            timeout: None,
        }
    }

    /// The same client with a time limit for [`call`](Self::call).
    pub fn with_timeout(mut self, timeout: Duration) -> Self {
        self.timeout = Some(timeout);
        self
    }

    /// The port's name.
    pub fn name(&self) -> &str {
        &self.core.name
    }

    /// The time limit of [`call`](Self::call), if any.
    pub fn timeout(&self) -> Option<Duration> {
        self.timeout
    }

    /// Whether the client is connected to a service.
    pub fn is_connected(&self) -> bool {
        lock(&self.core.state).service.is_some()
    }

    /// The name of the service the client is connected to.
    pub fn service_name(&self) -> Option<String> {
        lock(&self.core.state)
            .service
            .as_ref()
            .map(|s| s.name.clone())
    }

    /// Registers the notifier called when the answer to an asynchronous call arrives
    /// (once per port; a data-triggered container registers its wakeup). Gives it back
    /// if one is already set. Called on the answering thread: keep it short.
    pub fn set_notifier(&self, notifier: Notifier) -> Result<(), Notifier> {
        self.core.set_notifier(notifier)
    }

    /// A type-erased handle for wiring by name (the runtime builder's use).
    pub fn handle(&self) -> super::ClientHandle {
        super::ClientHandle::new(&self.core)
    }

    /// Calls the service and waits for the answer — at most the client's
    /// [`timeout`](Self::timeout), if it has one. The thread sleeps while it waits.
    pub fn call(&self, request: Req) -> Result<Resp, CallError> {
        let deadline = self.timeout.and_then(|t| Instant::now().checked_add(t));
        self.call_until(request, deadline)
    }

    /// Calls the service and waits at most `timeout` for the answer; then fails with
    /// [`CallError::Timeout`]. A request the server accepted is executed even so; its
    /// answer is dropped. The limit does not interrupt a caller-executed handler.
    pub fn call_timeout(&self, request: Req, timeout: Duration) -> Result<Resp, CallError> {
        self.call_until(request, Instant::now().checked_add(timeout))
    }

    fn call_until(&self, request: Req, deadline: Option<Instant>) -> Result<Resp, CallError> {
        match self.submit(request, false)? {
            Submitted::Done(response) => Ok(response),
            Submitted::Queued(slot) => slot.wait(deadline).unwrap_or(Err(CallError::Timeout)),
        }
    }

    /// Calls the service without waiting for the answer. Errors known at once
    /// (not connected, queue full, service stopped) come back at once; a
    /// caller-executed service has already run when this returns.
    pub fn call_async(&self, request: Req) -> Result<PendingResponse<Resp>, CallError> {
        Ok(match self.submit(request, true)? {
            Submitted::Done(response) => PendingResponse::ready(Ok(response)),
            Submitted::Queued(slot) => PendingResponse::queued(slot),
        })
    }

    /// Hands the request to the service: queued, or executed here if the service is
    /// caller-executed (outside every lock).
    fn submit(&self, request: Req, asynchronous: bool) -> Result<Submitted<Resp>, CallError> {
        let state = lock(&self.core.state);
        let service = state.service.as_ref().ok_or(CallError::NotConnected)?;
        if service.is_inline() {
            let service = Arc::clone(service);
            drop(state);
            return service.call_inline(request).map(Submitted::Done);
        }
        let reply_notifier = if asynchronous {
            state.notifier.clone()
        } else {
            None
        };
        let (slot, server_notifier) =
            service.enqueue(ClientCore::id(&self.core), request, reply_notifier)?;
        drop(state);
        if let Some(n) = server_notifier {
            n.notify();
        }
        Ok(Submitted::Queued(slot))
    }

    /// Disconnects the client from its service; false if it was not connected. Its
    /// queued requests fail with [`CallError::Disconnected`]; a request the server
    /// already took is answered normally.
    pub fn disconnect(&self) -> bool {
        let mut state = lock(&self.core.state);
        let was_connected = state.service.is_some();
        let withdrawn = ClientCore::unlink(&self.core, &mut state);
        drop(state);
        drop(withdrawn);
        was_connected
    }
}

impl<Req, Resp> Drop for ClientPort<Req, Resp> {
    fn drop(&mut self) {
        let mut state = lock(&self.core.state);
        let withdrawn = ClientCore::unlink(&self.core, &mut state);
        drop(state);
        drop(withdrawn);
    }
}

impl<Req, Resp> fmt::Debug for ClientPort<Req, Resp> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("ClientPort")
            .field("name", &self.core.name)
            .field("timeout", &self.timeout)
            .finish_non_exhaustive()
    }
}

/// See [`super::connect`].
pub(crate) fn connect<Req, Resp>(
    client: &ClientPort<Req, Resp>,
    service: &ServicePort<Req, Resp>,
) -> Result<(), ServiceConnectError> {
    connect_cores(&client.core, &service.core)
}

/// [`connect`] on the shared cores (what type-erased handles hold).
pub(crate) fn connect_cores<Req, Resp>(
    client: &Arc<ClientCore<Req, Resp>>,
    service: &Arc<ServerCore<Req, Resp>>,
) -> Result<(), ServiceConnectError> {
    let mut state = lock(&client.state);
    if let Some(current) = &state.service {
        return Err(if Arc::ptr_eq(current, service) {
            ServiceConnectError::AlreadyConnected {
                client: client.name.clone(),
                service: current.name.clone(),
            }
        } else {
            ServiceConnectError::ClientBusy {
                client: client.name.clone(),
                connected_to: current.name.clone(),
            }
        });
    }
    lock(&service.state).clients.push(Arc::clone(client));
    state.service = Some(Arc::clone(service));
    Ok(())
}

/// See [`super::disconnect`].
pub(crate) fn disconnect<Req, Resp>(
    client: &ClientPort<Req, Resp>,
    service: &ServicePort<Req, Resp>,
) -> bool {
    let mut state = lock(&client.core.state);
    if !state
        .service
        .as_ref()
        .is_some_and(|s| Arc::ptr_eq(s, &service.core))
    {
        return false;
    }
    let withdrawn = ClientCore::unlink(&client.core, &mut state);
    drop(state);
    drop(withdrawn);
    true
}
