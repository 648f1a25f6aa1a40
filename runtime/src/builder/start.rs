//! Starting a built application: free-running (a thread per container) or in
//! lockstep, with the links to other parts set up first.

use super::*;

/// How [`Builder::start_with`] runs the application.
#[derive(Clone, Debug, Default)]
pub struct StartOptions {
    /// Each container stops after this many cycles.
    pub limit: Option<u64>,
    /// Run in simulated time on one thread, the same way every time; `None`: every
    /// container on its own thread, in real time.
    pub lockstep: Option<Lockstep>,
    /// Where the other parts are; needed when links leave this process.
    pub network: Option<crate::link::net::Network>,
}

impl Builder<'_> {
    /// Creates the thread containers and starts them; each runs `limit` cycles, or
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
        let links = lockstep::Links {
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
