//! A started application: its containers, their figures, and a clean stop.

use super::BuildError;
use ferroc_exec::{ContainerStats, RunningContainer, ThreadContainer, ThreadOptions, Trigger};
use ferroc_link::Hub;
use ferroc_module::behaviour::{ViolationCount, ViolationLog};
use ferroc_module::resource::LockOrder;
use ferroc_module::{ParamHandle, Value};
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// The cycles each container runs when the application runs `limit` cycles (`--cycles
/// N`), and whether it ends the run (the run is over when those have ended, and the
/// others are stopped then, after their current cycle).
///
/// `--cycles N` counts cycles of the application, not of each container: N cycles of
/// its fastest periodic containers (those of the shortest period), which end the run;
/// slower periodic, continuous and data-triggered containers run until then. (Each
/// container counting N kept a slow container running long after the fast ones had
/// stopped.) In lockstep the same limit is exact: the instants before N times the
/// shortest period. Without periodic containers, each continuous one runs N cycles
/// (data-triggered ones until those end); with only data-triggered containers, each
/// runs N.
pub fn cycles_of(triggers: &[Trigger], limit: Option<u64>) -> Vec<(Option<u64>, bool)> {
    let shortest = triggers
        .iter()
        .filter_map(|t| match t {
            Trigger::Periodic(p) => Some(p.as_nanos().max(1)),
            _ => None,
        })
        .min();
    let any_continuous = triggers.iter().any(|t| matches!(t, Trigger::Continuous));
    triggers
        .iter()
        .map(|t| match (t, shortest) {
            (Trigger::Periodic(p), Some(min)) if p.as_nanos().max(1) == min => (limit, true),
            (_, Some(_)) => (None, false),
            (Trigger::Continuous, None) => (limit, true),
            (_, None) if any_continuous => (None, false),
            (_, None) => (limit, true),
        })
        .collect()
}

/// The figures of one container at a moment, for status lines and reports.
#[derive(Clone, Debug, PartialEq)]
pub struct ContainerStatus {
    /// Element path of the container.
    pub path: String,
    /// Cycles completed.
    pub cycles: u64,
    /// Cycles that missed their deadline.
    pub overruns: u64,
    /// Average share of the period spent executing (0 for data-triggered containers).
    pub load: f64,
}

/// An application whose thread containers are running.
pub struct RunningApp {
    containers: Vec<RunningContainer>,
    /// Kept apart from the threads so figures stay readable after [`join`](Self::join).
    stats: Vec<Arc<ContainerStats>>,
    stop: Arc<AtomicBool>,
    params: HashMap<(String, String), std::sync::Arc<ParamHandle>>,
    warnings: Vec<String>,
    lock_order: Arc<LockOrder>,
    violations: Arc<ViolationLog>,
    hub: Arc<Hub>,
    /// Why it ended by itself, when not by the cycle limit.
    end_reason: Arc<std::sync::OnceLock<&'static str>>,
    /// Why it could not go on (a part it is linked to is gone, in lockstep).
    failure: Arc<std::sync::OnceLock<String>>,
    /// Each free-running container's path, change slot and trigger (for
    /// reconfiguration while it runs; empty in lockstep).
    pub(super) slots: Vec<(String, Arc<ferroc_exec::ChangeSlot>, Trigger)>,
}

/// What a running application keeps besides its threads.
pub(super) struct Shared {
    pub params: HashMap<(String, String), std::sync::Arc<ParamHandle>>,
    pub lock_order: Arc<LockOrder>,
    pub violations: Arc<ViolationLog>,
    pub hub: Arc<Hub>,
    pub stop: Arc<AtomicBool>,
}

impl RunningApp {
    fn new(shared: Shared) -> Self {
        RunningApp {
            containers: Vec::new(),
            stats: Vec::new(),
            stop: shared.stop,
            params: shared.params,
            warnings: Vec::new(),
            lock_order: shared.lock_order,
            violations: shared.violations,
            hub: shared.hub,
            end_reason: Arc::default(),
            failure: Arc::default(),
            slots: Vec::new(),
        }
    }

    /// Why the application could not go on, if it failed: in lockstep, a part it is
    /// linked to is gone. A failed run is not a clean end.
    pub fn failure(&self) -> Option<&str> {
        self.failure.get().map(String::as_str)
    }

    /// What the network between parts reports now, a line each: a linked part that is
    /// gone, and since when (`link robot → station: part robot gone since 3.2 s`).
    /// Empty while all is well, and for an application without links to other programs.
    pub fn network_status(&self) -> Vec<String> {
        self.hub.status()
    }

    /// Why the application ended by itself: the cycle limit, or in lockstep with a
    /// time limit, model time.
    pub fn end_reason(&self) -> &'static str {
        if self.failure.get().is_some() {
            return "failed";
        }
        self.end_reason
            .get()
            .copied()
            .unwrap_or("cycle limit reached")
    }

    /// Runs `driver` on one thread that executes every container itself (lockstep).
    pub(super) fn start_driver(
        stats: Vec<Arc<ContainerStats>>,
        shared: Shared,
        driver: impl FnOnce(&AtomicBool) -> Result<Option<&'static str>, String> + Send + 'static,
    ) -> Result<Self, BuildError> {
        let mut app = RunningApp::new(shared);
        let stop = app.stop.clone();
        let (reason, failure) = (Arc::clone(&app.end_reason), Arc::clone(&app.failure));
        let join = std::thread::Builder::new()
            .name("lockstep".into())
            .spawn(move || {
                ferroc_ports::stopping::watch(Arc::clone(&stop));
                match driver(&stop) {
                    Ok(Some(why)) => {
                        let _ = reason.set(why);
                    }
                    Ok(None) => {}
                    Err(why) => {
                        ferroc_ports::console::note(&format!("error: {why}"));
                        let _ = failure.set(why);
                    }
                }
            })
            .map_err(|e| BuildError::Thread(format!("the lockstep thread could not start: {e}")))?;
        let first = stats.first().cloned().unwrap_or_else(|| {
            Arc::new(ContainerStats::new(
                "lockstep".into(),
                Vec::new(),
                None,
                false,
            ))
        });
        app.containers.push(RunningContainer::driver(first, join));
        app.stats = stats;
        Ok(app)
    }

    pub(super) fn start(
        containers: Vec<(ThreadContainer, ThreadOptions)>,
        shared: Shared,
        limit: Option<u64>,
    ) -> Result<Self, BuildError> {
        let mut app = RunningApp::new(shared);
        let stop = app.stop.clone();
        let mut refusals = Vec::new();
        let triggers: Vec<Trigger> = containers
            .iter()
            .map(|(c, _)| c.trigger().clone())
            .collect();
        let limits = cycles_of(&triggers, limit);
        for ((container, options), (limit, ends_run)) in containers.into_iter().zip(limits) {
            let name = container.stats().name.clone();
            let trigger = container.trigger().clone();
            app.slots.push((name.clone(), container.changes(), trigger));
            match container.spawn(options, stop.clone(), limit) {
                Ok(mut running) => {
                    running.ends_run = ends_run;
                    refusals.extend(running.refusals.iter().map(|r| (name.clone(), r.clone())));
                    app.stats.push(running.stats.clone());
                    app.containers.push(running);
                }
                Err(e) => {
                    app.stop();
                    app.join();
                    return Err(BuildError::Thread(format!(
                        "thread container `{name}` could not start: {e}"
                    )));
                }
            }
        }
        app.warnings = ferroc_exec::summarise_refusals(&refusals);
        Ok(app)
    }

    /// What the operating system refused (priorities, CPU affinity), one line each.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// The statistics of every container, in declaration order (also after `join`).
    pub fn stats(&self) -> Vec<Arc<ContainerStats>> {
        self.stats.clone()
    }

    /// A snapshot of every container's figures (also after `join`).
    pub fn status(&self) -> Vec<ContainerStatus> {
        self.stats
            .iter()
            .map(|s| ContainerStatus {
                path: s.name.clone(),
                cycles: s.cycles(),
                overruns: s.overruns(),
                load: s.load(),
            })
            .collect()
    }

    /// Lock-order problems seen so far (inversions, level violations, recursive
    /// locks), each with its acquisition sites; also readable after `join`.
    pub fn lock_reports(&self) -> Vec<String> {
        self.lock_order.reports()
    }

    /// Panic reports of stopped steps, each naming the module path (also after `join`).
    pub fn panics(&self) -> Vec<String> {
        self.stats.iter().flat_map(|s| s.panics()).collect()
    }

    /// iB2C principle violations reported since the last call, each naming the module
    /// path, the rule and the values (rate-limited per module and rule by the policy).
    pub fn take_violation_reports(&self) -> Vec<String> {
        self.violations.take_reports()
    }

    /// How often each behaviour violated each rule so far (also after `join`); reports
    /// dropped unread are in [`violation_reports_dropped`](Self::violation_reports_dropped).
    pub fn violation_counts(&self) -> Vec<ViolationCount> {
        self.violations.counts()
    }

    /// Violation reports dropped because they were not taken in time.
    pub fn violation_reports_dropped(&self) -> u64 {
        self.violations.dropped()
    }

    /// Sets a module's parameter while the application runs.
    pub fn set_parameter(&self, path: &str, name: &str, value: &Value) -> Result<(), String> {
        let handle = self
            .params
            .get(&(path.to_owned(), name.to_owned()))
            .ok_or_else(|| format!("`{path}` has no parameter `{name}`"))?;
        handle.set(value)
    }

    /// Whether the application has ended: every container that ends the run (see
    /// [`cycles_of`]) reached its cycle limit or stopped. Data-triggered containers do
    /// not count when there are others: they run only as often as data arrives, which
    /// may be fewer times than the limit, so waiting for them could take forever.
    pub fn is_finished(&self) -> bool {
        self.containers
            .iter()
            .filter(|c| c.ends_run)
            .all(|c| c.is_finished())
    }

    /// Asks every container to stop after its current cycle (also wakes data-triggered
    /// ones).
    pub fn stop(&self) {
        self.stop.store(true, Ordering::Relaxed);
        for c in &self.containers {
            c.nudge();
        }
    }

    /// Waits until every container has ended (and closes the links to other parts).
    pub fn join(&mut self) {
        for c in self.containers.drain(..) {
            c.join();
        }
        self.hub.close();
    }

    /// Waits until every container has ended, but no longer than `grace`; returns the
    /// paths of those still running then, which are left behind (their threads end
    /// with the process). A step that never returns (a module looping or blocked
    /// outside the port core) must not keep a stopped run from exiting.
    pub fn join_within(&mut self, grace: Duration) -> Vec<String> {
        let deadline = std::time::Instant::now() + grace;
        while self.containers.iter().any(|c| !c.is_finished())
            && std::time::Instant::now() < deadline
        {
            std::thread::sleep(Duration::from_millis(5));
        }
        let mut stuck = Vec::new();
        for c in self.containers.drain(..) {
            if c.is_finished() {
                c.join();
            } else {
                stuck.push(c.stats.name.clone());
            }
        }
        self.hub.close();
        stuck
    }

    /// Waits until every container ended or `timeout` passed; true if all ended.
    pub fn wait_timeout(&self, timeout: Duration) -> bool {
        let deadline = std::time::Instant::now() + timeout;
        while !self.is_finished() {
            if std::time::Instant::now() >= deadline {
                return false;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
        true
    }
}

impl Drop for RunningApp {
    /// Dropping a running application stops it and waits for its threads.
    fn drop(&mut self) {
        self.stop();
        self.join();
    }
}
