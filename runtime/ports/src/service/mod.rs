//! Services: request/response ports (the model's `<service>` and `<client>`).
//!
//! A module that offers a service owns a [`ServicePort<Req, Resp>`]; a module that
//! calls one owns a [`ClientPort<Req, Resp>`]. [`connect`] links a client to one
//! service (a service has any number of clients) and may be undone and redone while
//! running. Request and response types are part of both port types, so connecting a
//! client to a service of other types does not compile.
//!
//! Who executes a request is the service's choice (`<service executes=…>`):
//!
//! * **server** (the default): the request waits in the service's bounded queue until
//!   the serving module's step serves it ([`ServicePort::serve_pending`]). The handler
//!   runs on the server's thread container, so it can use the module's state through
//!   `&mut self` without locks. A queued request calls the service's notifier, so a
//!   data-triggered container can be woken by calls as by data.
//! * **caller**: the handler runs inline on the caller's thread
//!   ([`ServicePort::executed_by_caller`]); it is `Fn + Send + Sync`, and state it
//!   shares with its module must be synchronised.
//!
//! A client calls blocking ([`ClientPort::call`], [`ClientPort::call_timeout`]) or
//! asynchronously ([`ClientPort::call_async`] → [`PendingResponse`], polled with
//! [`PendingResponse::try_take`] or waited for). Failures are values ([`CallError`]),
//! never hangs: not connected, timed out, queue full, server gone or disconnected while
//! the request waited, handler panicked.
//!
//! ```
//! use std::time::Duration;
//! use ferroc_ports::port::Wakeup;
//! use ferroc_ports::service::{connect, CallError, ClientPort, ServicePort};
//!
//! let square = ServicePort::<i64, i64>::new("square");        // executes="server"
//! let client = ClientPort::<i64, i64>::new("calculator");
//! assert_eq!(client.call(2), Err(CallError::NotConnected));    // an error, no hang
//! connect(&client, &square)?;
//!
//! // Asynchronous: the request waits until the server's step serves it.
//! let pending = client.call_async(3)?;
//! assert!(!pending.is_ready());
//! assert_eq!(square.serve_pending(|x| x * x), 1);              // in the server's step
//! assert_eq!(pending.try_take().ok(), Some(Ok(9)));
//!
//! // Blocking, from another thread; the service's notifier wakes the "server".
//! let wakeup = Wakeup::new();
//! square.set_notifier(wakeup.clone()).unwrap();
//! std::thread::scope(|s| {
//!     let caller = s.spawn(|| client.call(4));
//!     wakeup.wait();                                           // a request arrived
//!     square.serve_pending(|x| x * x);
//!     assert_eq!(caller.join().unwrap(), Ok(16));
//! });
//!
//! // Nobody serves: a time limit turns the wait into an error.
//! assert_eq!(client.call_timeout(5, Duration::from_millis(1)), Err(CallError::Timeout));
//!
//! // executes="caller": the handler runs inline on the calling thread.
//! let add_one = ServicePort::<i64, i64>::executed_by_caller("add_one", |x| x + 1);
//! client.disconnect();
//! connect(&client, &add_one)?;
//! assert_eq!(client.call(41), Ok(42));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Mismatched types do not compile:
//!
//! ```compile_fail
//! use ferroc_ports::service::{connect, ClientPort, ServicePort};
//! let service = ServicePort::<f64, bool>::new("relocalize");
//! let client = ClientPort::<f64, f64>::new("caller");
//! connect(&client, &service);
//! ```
//!
//! Where to read on: `reply.rs` (the one-shot answer slot, and why a request can never
//! be left unanswered), `server.rs` (queue, execution, panics, drop), `client.rs`
//! (calls, and connecting without losing a request to a concurrent disconnect).
//! `docs/runtime-services.md` shows a whole module pair.

mod client;
mod handle;
mod reply;
mod server;

use std::fmt;

pub use client::ClientPort;
pub use handle::{ClientHandle, ServiceHandle};
pub use reply::{PendingResponse, Responder};
pub use server::{Request, ServicePort};

/// Who executes a service's requests (`<service executes=…>`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Executes {
    /// The serving module's thread container, in its own step (the default).
    #[default]
    Server,
    /// Each caller, inline on its own thread.
    Caller,
}

/// Why a call produced no response.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum CallError {
    /// The client is not connected to a service (or its service was dropped). The
    /// request was not sent.
    NotConnected,
    /// No answer within the time limit. The request may still be executed.
    Timeout,
    /// The request was accepted but will never be answered: the service was dropped,
    /// or the client was disconnected, while it waited in the queue, or the server
    /// dropped it unanswered.
    Disconnected,
    /// The service's queue was full; the request was not sent. Retrying later may
    /// succeed.
    QueueFull,
    /// A handler of the service panicked — while executing this request, or before,
    /// which stopped the service.
    ServerPanicked,
}

impl fmt::Display for CallError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            CallError::NotConnected => "the client is not connected to a service",
            CallError::Timeout => "no response within the time limit",
            CallError::Disconnected => "the service went away before answering",
            CallError::QueueFull => "the service's request queue is full",
            CallError::ServerPanicked => "the service's handler panicked",
        })
    }
}

impl std::error::Error for CallError {}

/// Why a client was not connected to a service.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum ServiceConnectError {
    /// The client is already connected to this service (nothing changed).
    AlreadyConnected {
        /// Name of the client port.
        client: String,
        /// Name of the service port.
        service: String,
    },
    /// The client is connected to another service; a client has one service at most.
    /// Disconnect it first.
    ClientBusy {
        /// Name of the client port.
        client: String,
        /// Name of the service it is connected to.
        connected_to: String,
    },
    /// The client's request or response type differs from the service's (only
    /// possible when wiring by name, through handles).
    TypeMismatch {
        /// The client: name (request → response).
        client: String,
        /// The service: name (request → response).
        service: String,
    },
}

impl fmt::Display for ServiceConnectError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ServiceConnectError::AlreadyConnected { client, service } => {
                write!(f, "client `{client}` is already connected to `{service}`")
            }
            ServiceConnectError::ClientBusy {
                client,
                connected_to,
            } => write!(
                f,
                "client `{client}` is connected to `{connected_to}`; a client calls one \
                 service at a time (disconnect it first)"
            ),
            ServiceConnectError::TypeMismatch { client, service } => write!(
                f,
                "client {client} cannot call service {service}: request and response \
                 types must be the same"
            ),
        }
    }
}

impl std::error::Error for ServiceConnectError {}

/// Connects `client` to `service`: from now on its calls go to that service. Fails if
/// the client is connected already (to this or another service).
pub fn connect<Req: Send + 'static, Resp: Send + 'static>(
    client: &ClientPort<Req, Resp>,
    service: &ServicePort<Req, Resp>,
) -> Result<(), ServiceConnectError> {
    client::connect(client, service)
}

/// Disconnects `client` from `service`; false if it was not connected to it. The
/// client's queued requests fail with [`CallError::Disconnected`]; a request the
/// server already took is answered normally.
pub fn disconnect<Req: Send + 'static, Resp: Send + 'static>(
    client: &ClientPort<Req, Resp>,
    service: &ServicePort<Req, Resp>,
) -> bool {
    client::disconnect(client, service)
}

#[cfg(test)]
mod tests;
