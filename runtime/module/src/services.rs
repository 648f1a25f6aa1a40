//! Declaring services and clients in `create`, next to ports and parameters.
//!
//! ```
//! # use ferroc_module::*;
//! # use ferroc_ports::service::{ClientPort, ServicePort};
//! # use std::time::Duration;
//! struct Localizer { relocalize: ServicePort<f64, bool>, heading: f64 }
//! impl Module for Localizer {
//!     fn update(&mut self) {
//!         let heading = &mut self.heading;
//!         // Requests queued since the last step are answered here, on this container.
//!         self.relocalize.serve_pending(|guess| {
//!             *heading = guess;
//!             true
//!         });
//!     }
//! }
//! impl ModuleType for Localizer {
//!     const NAME: &'static str = "demo.Localizer";
//!     fn create(m: &mut Setup<'_>) -> Self {
//!         Localizer { relocalize: m.service("relocalize").build(), heading: 0.0 }
//!     }
//! }
//!
//! struct Planner { relocalize: ClientPort<f64, bool> }
//! impl Module for Planner {
//!     fn update(&mut self) {
//!         // Not connected, timed out, server gone: all values, never a hang.
//!         let _accepted = self.relocalize.call(1.5);
//!     }
//! }
//! impl ModuleType for Planner {
//!     const NAME: &'static str = "demo.Planner";
//!     fn create(m: &mut Setup<'_>) -> Self {
//!         Planner {
//!             relocalize: m.client("relocalize").timeout(Duration::from_millis(20)).build(),
//!         }
//!     }
//! }
//! ```

use super::interface::ServiceInfo;
use super::setup::Setup;
use super::value::PortValue;
use ferroc_ports::service::{ClientPort, Executes, ServicePort};
use std::time::Duration;

/// A `<service>` declaration under way; finish with [`build`](ServiceDecl::build) or
/// [`executed_by_caller`](ServiceDecl::executed_by_caller).
pub struct ServiceDecl<'s, 'a> {
    setup: &'s mut Setup<'a>,
    info: ServiceInfo,
    capacity: usize,
}

/// A `<client>` declaration under way; finish with [`build`](ClientDecl::build).
pub struct ClientDecl<'s, 'a> {
    setup: &'s mut Setup<'a>,
    info: ServiceInfo,
}

fn info(name: &str, client: bool) -> ServiceInfo {
    ServiceInfo {
        name: name.to_owned(),
        client,
        request: String::new(),
        response: String::new(),
        executes: Executes::Server,
        timeout: None,
        doc: None,
    }
}

impl<'a> Setup<'a> {
    /// Declares a service this module answers (`<service name request response>`).
    /// With [`build`](ServiceDecl::build) the module's own step serves it (`executes=
    /// "server"`); calls wake a data-triggered container like data does.
    pub fn service(&mut self, name: &str) -> ServiceDecl<'_, 'a> {
        ServiceDecl {
            setup: self,
            info: info(name, false),
            capacity: ServicePort::<(), ()>::DEFAULT_CAPACITY,
        }
    }

    /// Declares a client this module calls a service with (`<client name request
    /// response timeout>`).
    pub fn client(&mut self, name: &str) -> ClientDecl<'_, 'a> {
        ClientDecl {
            setup: self,
            info: info(name, true),
        }
    }

    fn record_service(&mut self, info: ServiceInfo) {
        self.refuse_taken_name(&info.name);
        self.interface.services.push(info);
    }
}

impl ServiceDecl<'_, '_> {
    /// A one-line description.
    pub fn doc(mut self, doc: &str) -> Self {
        self.info.doc = Some(doc.to_owned());
        self
    }

    /// At most `n` requests wait for the server's step (default 16); a call finding the
    /// queue full fails at once with `QueueFull`.
    pub fn capacity(mut self, n: usize) -> Self {
        self.capacity = n;
        self
    }

    /// Creates the service, answered by the module's step (`serve_pending`).
    pub fn build<Req: PortValue, Resp: PortValue>(self) -> ServicePort<Req, Resp> {
        let port = ServicePort::with_capacity(self.info.name.clone(), self.capacity);
        self.finish(port)
    }

    /// Creates a service whose handler runs inline on each caller's thread
    /// (`executes="caller"`); see [`ServicePort::executed_by_caller`].
    pub fn executed_by_caller<Req: PortValue, Resp: PortValue>(
        mut self,
        handler: impl Fn(Req) -> Resp + Send + Sync + 'static,
    ) -> ServicePort<Req, Resp> {
        self.info.executes = Executes::Caller;
        let port = ServicePort::executed_by_caller(self.info.name.clone(), handler);
        self.finish(port)
    }

    fn finish<Req: PortValue, Resp: PortValue>(
        self,
        port: ServicePort<Req, Resp>,
    ) -> ServicePort<Req, Resp> {
        let ServiceDecl {
            setup, mut info, ..
        } = self;
        info.request = Req::model_type();
        info.response = Resp::model_type();
        setup.services.push((info.name.clone(), port.handle()));
        setup.record_service(info);
        port
    }
}

impl ClientDecl<'_, '_> {
    /// A one-line description.
    pub fn doc(mut self, doc: &str) -> Self {
        self.info.doc = Some(doc.to_owned());
        self
    }

    /// A blocking call waits at most this long (the manifest's `timeout`); without
    /// it, until answered.
    pub fn timeout(mut self, timeout: Duration) -> Self {
        self.info.timeout = Some(timeout);
        self
    }

    /// Creates the client; unconnected, its calls fail with `NotConnected`.
    pub fn build<Req: PortValue, Resp: PortValue>(self) -> ClientPort<Req, Resp> {
        let ClientDecl { setup, mut info } = self;
        info.request = Req::model_type();
        info.response = Resp::model_type();
        let mut port = ClientPort::new(info.name.clone());
        if let Some(t) = info.timeout {
            port = port.with_timeout(t);
        }
        setup.clients.push((info.name.clone(), port.handle()));
        setup.record_service(info);
        port
    }
}
