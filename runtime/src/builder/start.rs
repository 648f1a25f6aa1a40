//! Starting a built application: free-running (a thread per container) or in
//! lockstep, with the links to other parts set up first.

use super::*;
use crate::link::net::{self, Network, Outgoing, Sink};
use crate::link::{Hub, Inbox, Route};
use std::collections::BTreeSet;
use std::sync::atomic::AtomicBool;

/// How [`Builder::start_with`] runs the application.
#[derive(Clone, Debug, Default)]
pub struct StartOptions {
    /// The application stops after this many cycles of its fastest periodic
    /// containers (see [`cycles_of`]).
    pub limit: Option<u64>,
    /// Run in simulated time on one thread, the same way every time; `None`: every
    /// container on its own thread, in real time.
    pub lockstep: Option<Lockstep>,
    /// Where the other parts are; needed when links leave this process.
    pub network: Option<crate::link::net::Network>,
}

impl Builder<'_> {
    /// Creates the thread containers and starts them; the application runs `limit`
    /// cycles ([`cycles_of`]), or
    /// until [`RunningApp::stop`].
    pub fn start(self, limit: Option<u64>) -> Result<RunningApp, BuildError> {
        self.start_with(StartOptions {
            limit,
            ..StartOptions::default()
        })
    }

    /// Creates the thread containers and starts them as `options` say.
    pub fn start_with(mut self, options: StartOptions) -> Result<RunningApp, BuildError> {
        if let Some(m) = self
            .modules
            .iter()
            .find(|m| m.thread.is_none() && !m.link_end)
        {
            return Err(BuildError::Thread(format!(
                "`{}` is not executed by any thread container",
                m.path
            )));
        }
        self.bind_remaining_locks();
        let containers = self.containers()?;
        let params = self.take_params();
        let stop = Arc::new(std::sync::atomic::AtomicBool::new(false));
        let inbox = Arc::new(crate::link::Inbox::new(
            std::mem::take(&mut self.receiving),
            std::mem::take(&mut self.direct_ends),
        ));
        let shared = running::Shared {
            params,
            lock_order: Arc::clone(&self.lock_order),
            violations: self.violations.clone(),
            hub: Arc::clone(&self.hub),
            stop: Arc::clone(&stop),
        };
        let links = Links {
            hub: Arc::clone(&self.hub),
            inbox,
            network: options.network,
            // Only links with one end elsewhere need the network.
            receiving_from: (self.received.iter())
                .filter(|(id, _)| !self.sent.contains_key(id))
                .map(|(_, part)| part.clone())
                .collect(),
            sending_to: (self.sent.iter())
                .filter(|(id, _)| !self.received.contains_key(id))
                .map(|(_, part)| part.clone())
                .collect(),
        };
        match options.lockstep {
            Some(lockstep) => lockstep.start(containers, links, shared, options.limit),
            None => {
                links.start_direct(&stop).map_err(BuildError::Connect)?;
                RunningApp::start(containers, shared, options.limit)
            }
        }
    }

    fn take_params(&mut self) -> HashMap<(String, String), Arc<ParamHandle>> {
        let mut params = HashMap::new();
        for m in &mut self.modules {
            for (name, handle) in m.params.drain(..) {
                params.insert((m.path.clone(), name), handle);
            }
        }
        params
    }
}

/// The links of the application being started.
pub(super) struct Links {
    pub hub: Arc<Hub>,
    pub inbox: Arc<Inbox>,
    pub network: Option<Network>,
    pub receiving_from: BTreeSet<String>,
    pub sending_to: BTreeSet<String>,
}

impl Links {
    pub(super) fn remote(&self) -> bool {
        !self.receiving_from.is_empty() || !self.sending_to.is_empty()
    }

    pub(super) fn network(&self) -> Result<&Network, String> {
        self.network.as_ref().ok_or_else(|| {
            let parts: Vec<&String> = self.receiving_from.union(&self.sending_to).collect();
            format!("this part is linked to {parts:?} but no network addresses were given")
        })
    }

    /// Running freely: values go out as soon as they are sent and are published as
    /// soon as they arrive.
    pub(super) fn start_direct(self, stop: &Arc<AtomicBool>) -> Result<(), String> {
        let mut outgoing = None;
        if self.remote() {
            let network = self.network()?;
            outgoing = Some(Outgoing::start(network, &self.sending_to, stop, true)?);
            if !self.receiving_from.is_empty() {
                let sink = Sink::Deliver(Arc::clone(&self.inbox));
                net::listen(network, self.receiving_from.clone(), sink, stop)?;
            }
        }
        self.hub.set_route(Route::Direct {
            inbox: self.inbox,
            network: outgoing,
        });
        Ok(())
    }
}
