//! Starting a built application: free-running (a thread per container) or in
//! lockstep, with the links to other parts set up first.

use super::{reconfigure, running, BuildError, Builder, Lockstep, RunningApp};
use ferroc_link::transport::{Connection, Delivery, Network, PartLinks};
use ferroc_link::{Hub, Inbox, Route};
use ferroc_module::ParamHandle;
use std::collections::HashMap;
use std::sync::Arc;

/// How [`Builder::start_with`] runs the application.
#[derive(Clone, Default)]
pub struct StartOptions {
    /// The application stops after this many cycles of its fastest periodic
    /// containers (see [`cycles_of`]).
    pub limit: Option<u64>,
    /// Run in simulated time on one thread, the same way every time; `None`: every
    /// container on its own thread, in real time.
    pub lockstep: Option<Lockstep>,
    /// The network to the other parts; needed when links leave this process
    /// (`ferroc_zenoh::Zenoh` in generated programs).
    pub network: Option<Arc<dyn Network>>,
}

impl std::fmt::Debug for StartOptions {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StartOptions")
            .field("limit", &self.limit)
            .field("lockstep", &self.lockstep)
            .field("network", &self.network.as_ref().map(|_| "…"))
            .finish()
    }
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
    pub fn start_with(self, options: StartOptions) -> Result<RunningApp, BuildError> {
        self.launch(options).map(|(app, _)| app)
    }

    /// [`start_with`](Self::start_with), giving back what the builder knew of the
    /// modules (their ports, parameters and containers) for reconfiguration.
    pub(super) fn launch(
        mut self,
        options: StartOptions,
    ) -> Result<(RunningApp, reconfigure::Leftovers), BuildError> {
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
        self.check_local_claims()?;
        self.bind_remaining_locks();
        self.give_lenders();
        let specs = self.threads.clone();
        let containers = self.containers()?;
        let params = self.take_params();
        let stop = Arc::new(std::sync::atomic::AtomicBool::new(false));
        let inbox = Arc::new(ferroc_link::Inbox::new(
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
            remote: only_remote(std::mem::take(&mut self.remote)),
        };
        if options.lockstep.is_some() {
            self.run.start_lockstep();
        }
        let app = match options.lockstep {
            Some(lockstep) => lockstep.start(containers, links, shared, options.limit)?,
            None => {
                links.start_direct().map_err(BuildError::Connect)?;
                RunningApp::start(containers, shared, options.limit)?
            }
        };
        let leftovers = reconfigure::Leftovers {
            modules: std::mem::take(&mut self.modules),
            threads: specs,
            connections: std::mem::take(&mut self.connections),
            inspected: std::mem::take(&mut self.inspected),
            violations: self.violations.clone(),
            run: Arc::clone(&self.run),
        };
        Ok((app, leftovers))
    }

    fn take_params(&mut self) -> HashMap<(String, String), Arc<ParamHandle>> {
        let mut params = HashMap::new();
        for m in &mut self.modules {
            for (name, handle) in &m.params {
                params.insert((m.path.clone(), name.clone()), Arc::clone(handle));
            }
        }
        params
    }
}

/// The links and calls with one end elsewhere: those with both ends built here are
/// delivered in the process.
fn only_remote(mut links: PartLinks) -> PartLinks {
    let both: Vec<u32> = (links.sending.keys())
        .filter(|id| links.receiving.contains_key(id))
        .copied()
        .collect();
    for id in both {
        links.sending.remove(&id);
        links.receiving.remove(&id);
    }
    let both: Vec<u32> = (links.calls_out.keys())
        .filter(|id| links.calls_in.contains_key(id))
        .copied()
        .collect();
    for id in both {
        links.calls_out.remove(&id);
        links.calls_in.remove(&id);
    }
    links
}

/// The links of the application being started.
pub(super) struct Links {
    pub hub: Arc<Hub>,
    pub inbox: Arc<Inbox>,
    pub network: Option<Arc<dyn Network>>,
    pub remote: PartLinks,
}

impl Links {
    /// Opens the network when links leave this process (`None` when none do).
    pub(super) fn open(&self, lockstep: bool) -> Result<Option<Box<dyn Connection>>, String> {
        if self.remote.is_empty() {
            return Ok(None);
        }
        let network = self.network.as_ref().ok_or_else(|| {
            if !self.remote.has_parts() {
                let nodes: Vec<&str> = (self.remote.ros2.iter()).map(|n| n.part.as_str()).collect();
                return format!(
                    "the part {} is a ROS 2 node, but this program has no network to \
                     ROS 2 (help: run the model with `ferroc run`, which starts it in a \
                     runner that speaks ROS 2)",
                    nodes.join(", ")
                );
            }
            let mut parts = self.remote.sends_to();
            parts.extend(self.remote.receives_from());
            let parts: Vec<&str> = parts.into_iter().collect();
            format!(
                "this part is linked to {} but no network to other parts was given",
                parts.join(", ")
            )
        })?;
        let delivery = Delivery::new(Arc::clone(&self.inbox));
        network.open(&self.remote, delivery, lockstep).map(Some)
    }

    /// Running freely: values go out as soon as they are sent and are published as
    /// soon as they arrive.
    pub(super) fn start_direct(self) -> Result<(), String> {
        let network = self.open(false)?;
        self.hub.set_route(Route::Direct {
            inbox: self.inbox,
            network,
        });
        Ok(())
    }
}
