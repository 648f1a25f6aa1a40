//! Timing statistics of a thread container, written by its thread and read by anyone
//! (the status line, introspection) without locks.

use std::sync::atomic::{AtomicU64, Ordering::Relaxed};
use std::sync::Mutex;
use std::time::Duration;

/// Per-step figures, updated after every execution of the step.
#[derive(Debug, Default)]
pub struct StepStats {
    runs: AtomicU64,
    total_nanos: AtomicU64,
    max_nanos: AtomicU64,
}

impl StepStats {
    pub(crate) fn record(&self, took: Duration) {
        let n = took.as_nanos().min(u64::MAX as u128) as u64;
        self.runs.fetch_add(1, Relaxed);
        self.total_nanos.fetch_add(n, Relaxed);
        self.max_nanos.fetch_max(n, Relaxed);
    }

    /// How often the step ran.
    pub fn runs(&self) -> u64 {
        self.runs.load(Relaxed)
    }

    /// Mean execution time, zero before the first run.
    pub fn mean(&self) -> Duration {
        let runs = self.runs();
        if runs == 0 {
            return Duration::ZERO;
        }
        Duration::from_nanos(self.total_nanos.load(Relaxed) / runs)
    }

    /// Longest execution time seen.
    pub fn max(&self) -> Duration {
        Duration::from_nanos(self.max_nanos.load(Relaxed))
    }
}

/// Figures of a whole container.
#[derive(Debug)]
pub struct ContainerStats {
    /// The container's name (its element path).
    pub name: String,
    /// One entry per step, in schedule order, with the step's name.
    pub steps: Vec<(String, StepStats)>,
    cycles: AtomicU64,
    overruns: AtomicU64,
    busy_nanos: AtomicU64,
    last_cycle_nanos: AtomicU64,
    period_nanos: u64,
    continuous: bool,
    panics: Mutex<Vec<String>>,
}

impl ContainerStats {
    #[doc(hidden)]
    pub fn new(
        name: String,
        step_names: Vec<String>,
        period: Option<Duration>,
        continuous: bool,
    ) -> Self {
        ContainerStats {
            name,
            steps: step_names
                .into_iter()
                .map(|n| (n, StepStats::default()))
                .collect(),
            cycles: AtomicU64::new(0),
            overruns: AtomicU64::new(0),
            busy_nanos: AtomicU64::new(0),
            last_cycle_nanos: AtomicU64::new(0),
            period_nanos: period.map_or(0, |p| p.as_nanos().min(u64::MAX as u128) as u64),
            continuous,
            panics: Mutex::new(Vec::new()),
        }
    }

    pub(crate) fn record_cycle(&self, took: Duration, overrun: bool) {
        let n = took.as_nanos().min(u64::MAX as u128) as u64;
        self.cycles.fetch_add(1, Relaxed);
        self.busy_nanos.fetch_add(n, Relaxed);
        self.last_cycle_nanos.store(n, Relaxed);
        if overrun {
            self.overruns.fetch_add(1, Relaxed);
        }
    }

    /// `cycles` cycles timed together (continuous containers); the last cycle's
    /// duration becomes their mean.
    pub(crate) fn record_cycles(&self, cycles: u64, took: Duration) {
        let n = took.as_nanos().min(u64::MAX as u128) as u64;
        self.cycles.fetch_add(cycles, Relaxed);
        self.busy_nanos.fetch_add(n, Relaxed);
        self.last_cycle_nanos.store(n / cycles.max(1), Relaxed);
    }

    pub(crate) fn record_panic(&self, message: String) {
        self.panics
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .push(message);
    }

    /// Cycles completed.
    pub fn cycles(&self) -> u64 {
        self.cycles.load(Relaxed)
    }

    /// Cycles that took longer than the period (periodic containers only).
    pub fn overruns(&self) -> u64 {
        self.overruns.load(Relaxed)
    }

    /// Mean time of a cycle over everything so far (zero before the first).
    pub fn mean_cycle(&self) -> Duration {
        let cycles = self.cycles();
        if cycles == 0 {
            return Duration::ZERO;
        }
        Duration::from_nanos(self.busy_nanos.load(Relaxed) / cycles)
    }

    /// Duration of the most recent cycle.
    pub fn last_cycle(&self) -> Duration {
        Duration::from_nanos(self.last_cycle_nanos.load(Relaxed))
    }

    /// Share of the period spent executing, averaged over all cycles (0 for
    /// data-triggered containers, which have no period; 1 for a running continuous
    /// container, which never sleeps).
    pub fn load(&self) -> f64 {
        let cycles = self.cycles();
        if self.continuous {
            return if cycles == 0 { 0.0 } else { 1.0 };
        }
        if self.period_nanos == 0 || cycles == 0 {
            return 0.0;
        }
        self.busy_nanos.load(Relaxed) as f64 / (cycles as f64 * self.period_nanos as f64)
    }

    /// Messages of steps that panicked (each such step is stopped).
    pub fn panics(&self) -> Vec<String> {
        self.panics
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone()
    }
}
