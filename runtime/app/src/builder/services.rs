//! Wiring clients to services by name, and waking serving containers on calls.

use super::{BuildError, Builder};
use ferroc_ports::port::{Notifier, Wakeup};
use ferroc_ports::service::Executes;

impl Builder<'_> {
    /// Connects the client `client` (module path, client name) to the service `service`
    /// (module path, service name). A client calls one service; a service has any
    /// number of clients. Request and response types must be the same.
    pub fn connect_service(
        &mut self,
        client: (&str, &str),
        service: (&str, &str),
    ) -> Result<(), BuildError> {
        let (caller, server) = (self.module(client.0)?, self.module(service.0)?);
        let c = super::find(&self.modules[caller].clients, client, "client")?;
        let s = super::find(&self.modules[server].services, service, "service")?;
        c.connect(s).map_err(|e| {
            BuildError::Connect(format!(
                "`{}/{}` → `{}/{}`: {e}",
                client.0, client.1, service.0, service.1
            ))
        })
    }

    /// In a data-triggered container: a request queued for one of module `m`'s
    /// services wakes it (the module's step serves it), and so does the answer to one
    /// of its asynchronous calls.
    pub(super) fn wake_on_calls(&self, m: usize, wakeup: &std::sync::Arc<Wakeup>) {
        let instance = &self.modules[m];
        for (_, service) in &instance.services {
            if service.executes() == Executes::Server {
                let notifier: Notifier = wakeup.clone();
                let _ = service.set_notifier(notifier);
            }
        }
        for (_, client) in &instance.clients {
            let notifier: Notifier = wakeup.clone();
            let _ = client.set_notifier(notifier);
        }
    }
}
