//! Type-erased handles on services and clients, for wiring by name.
//!
//! As with data ports ([`crate::port::OutputHandle`]), modules own their
//! [`ClientPort`](super::ClientPort)s and [`ServicePort`](super::ServicePort)s as typed
//! fields while the builder wires them knowing only names. A handle shares the port's
//! core (dropping the port still disconnects it) and remembers, as a function pointer
//! monomorphised for the request and response types, how to connect it. Connecting a
//! client to a service of other types is an error value, not a panic.

use super::client::{connect_cores, ClientCore};
use super::server::ServerCore;
use super::{Executes, ServiceConnectError};
use crate::port::Notifier;
use crate::sync::Arc;
use std::any::Any;

type ConnectFn = fn(&ClientHandle, &ServiceHandle) -> Result<(), ServiceConnectError>;
type NotifyFn = fn(&(dyn Any + Send + Sync), Notifier) -> Result<(), Notifier>;

/// A shared, type-erased reference to a client port's core.
pub struct ClientHandle {
    /// `Arc<ClientCore<Req, Resp>>`.
    core: Box<dyn Any + Send + Sync>,
    name: String,
    types: (&'static str, &'static str),
    connect: ConnectFn,
    set_notifier: NotifyFn,
}

/// A shared, type-erased reference to a service port's core.
pub struct ServiceHandle {
    /// `Arc<ServerCore<Req, Resp>>`.
    core: Box<dyn Any + Send + Sync>,
    name: String,
    types: (&'static str, &'static str),
    executes: Executes,
    set_notifier: NotifyFn,
}

impl ClientHandle {
    pub(crate) fn new<Req: Send + 'static, Resp: Send + 'static>(
        core: &Arc<ClientCore<Req, Resp>>,
    ) -> Self {
        ClientHandle {
            core: Box::new(Arc::clone(core)),
            name: core.name().to_owned(),
            types: (std::any::type_name::<Req>(), std::any::type_name::<Resp>()),
            connect: connect_erased::<Req, Resp>,
            set_notifier: |core, n| match core.downcast_ref::<Arc<ClientCore<Req, Resp>>>() {
                Some(core) => core.set_notifier(n),
                None => Err(n),
            },
        }
    }

    /// The port's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The Rust request and response types (for messages).
    pub fn types(&self) -> (&'static str, &'static str) {
        self.types
    }

    /// Connects this client to `service`; a service of other request or response
    /// types gives [`ServiceConnectError::TypeMismatch`].
    pub fn connect(&self, service: &ServiceHandle) -> Result<(), ServiceConnectError> {
        (self.connect)(self, service)
    }

    /// Registers the notifier called when an asynchronous call's answer arrives.
    pub fn set_notifier(&self, notifier: Notifier) -> Result<(), Notifier> {
        (self.set_notifier)(self.core.as_ref(), notifier)
    }
}

impl ServiceHandle {
    pub(crate) fn new<Req: Send + 'static, Resp: Send + 'static>(
        core: &Arc<ServerCore<Req, Resp>>,
        executes: Executes,
    ) -> Self {
        ServiceHandle {
            core: Box::new(Arc::clone(core)),
            name: core.name.clone(),
            types: (std::any::type_name::<Req>(), std::any::type_name::<Resp>()),
            executes,
            set_notifier: |core, n| match core.downcast_ref::<Arc<ServerCore<Req, Resp>>>() {
                Some(core) => core.set_notifier(n),
                None => Err(n),
            },
        }
    }

    /// The port's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The Rust request and response types (for messages).
    pub fn types(&self) -> (&'static str, &'static str) {
        self.types
    }

    /// Who executes its requests.
    pub fn executes(&self) -> Executes {
        self.executes
    }

    /// Registers the notifier every queued request calls (the serving container's
    /// wakeup, so that calls wake a data-triggered container).
    pub fn set_notifier(&self, notifier: Notifier) -> Result<(), Notifier> {
        (self.set_notifier)(self.core.as_ref(), notifier)
    }
}

fn connect_erased<Req: Send + 'static, Resp: Send + 'static>(
    client: &ClientHandle,
    service: &ServiceHandle,
) -> Result<(), ServiceConnectError> {
    match (
        client.core.downcast_ref::<Arc<ClientCore<Req, Resp>>>(),
        service.core.downcast_ref::<Arc<ServerCore<Req, Resp>>>(),
    ) {
        (Some(c), Some(s)) => connect_cores(c, s),
        _ => Err(ServiceConnectError::TypeMismatch {
            client: format!("{} ({} → {})", client.name, client.types.0, client.types.1),
            service: format!(
                "{} ({} → {})",
                service.name, service.types.0, service.types.1
            ),
        }),
    }
}
