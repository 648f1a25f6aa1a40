//! Thread containers: one OS thread each, running a fixed list of steps every cycle.
//!
//! The order of the steps is decided by the compiler's scheduling pass (`ferroc
//! schedule` prints it); a container only executes it. A container is either
//!
//! * periodic: cycles start at absolute deadlines `start + k·period`, so the rate does
//!   not drift with execution time; a cycle that ends after its deadline counts as an
//!   overrun and the container resumes at the next deadline still ahead (no burst of
//!   catch-up cycles), or
//! * data-triggered: a cycle runs whenever an input registered with the container's
//!   [`Wakeup`] receives data (with `wait="inline"` in the thread that delivered it,
//!   `inline.rs`), or
//! * continuous: cycles run back to back without sleeping. Timing every step would
//!   cost more than a small cycle itself (two clock reads and three atomic updates per
//!   step), so a continuous container runs its cycles in batches, times the first
//!   cycle of a batch step by step and the batch as a whole. A batch doubles while it
//!   takes less than [`BATCH_TIME`] (up to [`MAX_BATCH`] cycles) and halves while it
//!   takes more than twice that: the clock reads cost next to nothing per cycle, and a
//!   change still reaches the container within about a millisecond.
//!
//! A step that panics is caught, reported in the statistics with its name, and not run
//! again; the other steps keep running.
//!
//! While it runs cycles, a container's thread holds the session of its [`Home`]: the
//! connections the Builder made local to it are read and written only there, and
//! changes to them that other threads ask for are applied between cycles
//! ([`Session::boundary`], `ferroc_ports`' `port/local.rs`): before each periodic or data-triggered
//! cycle, and between the batches of a continuous one.
//!
//! This crate depends on `ferroc-ports` (ports, wakeups, the stop flag) and
//! `ferroc-module` (a step runs a [`Module`](ferroc_module::Module)), nothing above.

#![forbid(unsafe_code)]
#![warn(missing_docs)]

/// `eprintln!` that does not panic when standard error is closed or full (see
/// `ferroc_ports::console::stderr_line`); it shadows std's in this whole crate.
#[allow(unused_macros)] // nothing prints with it today; kept so that nothing uses std's
macro_rules! eprintln {
    ($($arg:tt)*) => {
        ferroc_ports::console::stderr_line(format_args!($($arg)*))
    };
}

mod change;
mod clock;
mod inline;
mod os;
mod stats;

pub use change::{Change, ChangeSlot};
pub use clock::{Clock, ManualClock, SystemClock};
/// A module asking to be stopped (defined with modules, which raise it).
pub use ferroc_module::StopStep;
pub use os::{pin_current_thread, summarise as summarise_refusals, Placement, Refusal};
pub use stats::{ContainerStats, StepStats};

use ferroc_ports::port::{Home, Session, WaitMode, Wakeup};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// One unit of work in a cycle: a module's `update`, `sense` or `control`.
pub struct Step {
    name: String,
    work: Work,
    stopped: bool,
    /// Its figures in the container's statistics (`None`: a step a change added,
    /// counted only in the cycle figures).
    stat: Option<usize>,
}

/// What a step calls.
enum Work {
    /// A plain module's `update`, called directly: one indirect call a step instead of
    /// two through a closure (a step of the B2 ring costs ~10 ns in all).
    Update(Box<dyn ferroc_module::Module>),
    Call(Box<dyn FnMut() + Send>),
}

impl Step {
    /// A step called `name` (the module path and step kind, for reports).
    pub fn new(name: impl Into<String>, run: impl FnMut() + Send + 'static) -> Self {
        Self::with(name.into(), Work::Call(Box::new(run)))
    }

    /// A step calling `module.update()`.
    pub fn update(name: impl Into<String>, module: Box<dyn ferroc_module::Module>) -> Self {
        Self::with(name.into(), Work::Update(module))
    }

    fn with(name: String, work: Work) -> Self {
        Step {
            name,
            work,
            stopped: false,
            stat: None,
        }
    }

    #[inline]
    fn run(&mut self) {
        match &mut self.work {
            Work::Update(module) => module.update(),
            Work::Call(call) => call(),
        }
    }

    /// Its name.
    pub fn name(&self) -> &str {
        &self.name
    }
}

/// When a container runs a cycle.
#[derive(Clone)]
pub enum Trigger {
    /// At absolute deadlines `period` apart.
    Periodic(Duration),
    /// Whenever the wakeup is notified (register it on the triggering inputs).
    Data(Arc<Wakeup>),
    /// Back to back, without sleeping.
    Continuous,
}

/// The most cycles a continuous container runs in one batch (it times the steps of
/// one cycle per batch).
pub const MAX_BATCH: u64 = 4096;

/// A continuous container's batch grows while it takes less than this and shrinks
/// while it takes more than twice this.
pub const BATCH_TIME: Duration = Duration::from_micros(500);

/// The size of a continuous container's next batch after one of `ran` cycles (of
/// `size` asked for) took `took`.
fn next_batch(size: u64, ran: u64, took: Duration) -> u64 {
    if took > 2 * BATCH_TIME {
        (size / 2).max(1)
    } else if took < BATCH_TIME && ran == size {
        (size * 2).min(MAX_BATCH)
    } else {
        size
    }
}

/// Optional placement of the container's thread. Where the operating system refuses
/// (no permission for real-time priority, say), the container runs anyway and the
/// refusal is returned as a warning.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ThreadOptions {
    /// Real-time priority (SCHED_FIFO, 1–99 on Linux).
    pub priority: Option<i32>,
    /// The CPU the thread is pinned to.
    pub cpu: Option<usize>,
    /// How a data-triggered container waits for data (`wait=`; others ignore it).
    pub wait: WaitMode,
}

/// A container with its steps, not yet running.
pub struct ThreadContainer {
    trigger: Trigger,
    /// How a data-triggered container waits (from [`ThreadOptions::wait`] at spawn).
    wait: WaitMode,
    steps: Vec<Step>,
    stats: Arc<ContainerStats>,
    clock: Arc<dyn Clock>,
    /// Changes of its steps while it runs (`change.rs`).
    changes: Arc<ChangeSlot>,
    /// The owner of its local connections.
    home: ferroc_ports::sync::Arc<Home>,
}

impl ThreadContainer {
    /// A container called `name` (its element path) running `steps` in this order.
    pub fn new(name: impl Into<String>, trigger: Trigger, mut steps: Vec<Step>) -> Self {
        let period = match &trigger {
            Trigger::Periodic(p) => Some(*p),
            Trigger::Data(_) | Trigger::Continuous => None,
        };
        let continuous = matches!(trigger, Trigger::Continuous);
        let names = steps.iter().map(|s| s.name.clone()).collect();
        for (i, step) in steps.iter_mut().enumerate() {
            step.stat = Some(i);
        }
        ThreadContainer {
            trigger,
            wait: WaitMode::Park,
            steps,
            stats: Arc::new(ContainerStats::new(name.into(), names, period, continuous)),
            clock: Arc::new(SystemClock::default()),
            changes: Arc::default(),
            home: ferroc_ports::sync::Arc::new(Home::new()),
        }
    }

    /// Where changes of its steps are posted while it runs (see [`ChangeSlot`]).
    pub fn changes(&self) -> Arc<ChangeSlot> {
        Arc::clone(&self.changes)
    }

    /// The owner of the connections local to this container (the Builder makes them
    /// local with it before the container runs).
    #[doc(hidden)]
    pub fn home(&self) -> &ferroc_ports::sync::Arc<Home> {
        &self.home
    }

    /// Uses another clock (tests use [`ManualClock`]).
    pub fn with_clock(mut self, clock: Arc<dyn Clock>) -> Self {
        self.clock = clock;
        self
    }

    /// The statistics, shared with whoever wants to read them while it runs.
    pub fn stats(&self) -> Arc<ContainerStats> {
        Arc::clone(&self.stats)
    }

    /// When it runs a cycle.
    #[doc(hidden)]
    pub fn trigger(&self) -> &Trigger {
        &self.trigger
    }

    /// Runs every live step once, in order, timing each.
    pub fn run_cycle(&mut self) {
        let _session = Home::enter(&self.home);
        // Several containers may take turns on this thread (the lockstep driver).
        ferroc_module::cycle::set_period(self.period());
        let started = self.clock.now();
        let ended = self.execute_steps::<true>(started);
        self.stats
            .record_cycle(ended.saturating_sub(started), false);
        ferroc_module::cycle::leave_cycle();
    }

    /// The period of a periodic container, which its steps may read
    /// (`ferroc_module::cycle::period`).
    fn period(&self) -> Option<Duration> {
        match &self.trigger {
            Trigger::Periodic(p) => Some(*p),
            Trigger::Data(_) | Trigger::Continuous => None,
        }
    }

    /// Runs every live step once; `TIMED` records each step's execution time, from
    /// `started` (the clock's reading before the first step) on, and returns the
    /// reading after the last one. One reading a step: each step starts when the one
    /// before it ended (an inline container's cycle runs in a network callback, where
    /// two readings a step were a tenth of the cycle's instructions).
    fn execute_steps<const TIMED: bool>(&mut self, started: Duration) -> Duration {
        let mut t0 = started;
        for step in self.steps.iter_mut() {
            if step.stopped {
                continue;
            }
            let outcome = catch_unwind(AssertUnwindSafe(|| step.run()));
            if TIMED {
                let ended = self.clock.now();
                if let Some((_, stats)) = step.stat.and_then(|i| self.stats.steps.get(i)) {
                    stats.record(ended.saturating_sub(t0));
                }
                t0 = ended;
            }
            if let Err(payload) = outcome {
                step.stopped = true;
                self.stats.record_panic(stopped_note(&step.name, &*payload));
                if TIMED {
                    // The report is not the next step's time.
                    t0 = self.clock.now();
                }
            }
        }
        t0
    }

    /// Runs cycles on the current thread until `stop` is set or `limit` cycles ran.
    pub fn run(&mut self, stop: &AtomicBool, limit: Option<u64>) {
        let session = Home::enter(&self.home);
        ferroc_module::cycle::set_period(self.period());
        self.run_in(&session, stop, limit);
        ferroc_module::cycle::leave_cycle();
    }

    fn run_in(&mut self, session: &Session, stop: &AtomicBool, limit: Option<u64>) {
        let mut done = 0u64;
        let more = |done: u64| !stop.load(Ordering::Relaxed) && limit.is_none_or(|l| done < l);
        match self.trigger.clone() {
            Trigger::Periodic(period) => {
                let period = period.max(Duration::from_nanos(1));
                let mut deadline = self.clock.now() + period;
                while more(done) {
                    session.boundary();
                    let started = self.clock.now();
                    let ended = self.execute_steps::<true>(started);
                    let overrun = ended > deadline;
                    self.stats
                        .record_cycle(ended.saturating_sub(started), overrun);
                    done += 1;
                    if overrun {
                        // Keep the phase: resume at the first deadline still ahead.
                        let behind = (ended - deadline).as_nanos() / period.as_nanos();
                        deadline += period * (behind as u32).saturating_add(1);
                    }
                    if !more(done) {
                        break;
                    }
                    self.changes.apply_pending(&mut self.steps);
                    self.clock.sleep_until_or_stop(deadline, stop);
                    deadline += period;
                }
            }
            Trigger::Continuous => {
                let mut size = 1;
                while more(done) {
                    session.boundary();
                    let batch = limit.map_or(size, |l| (l - done).min(size));
                    let started = self.clock.now();
                    let mut ended = self.execute_steps::<true>(started);
                    let mut ran = 1;
                    while ran < batch && !stop.load(Ordering::Relaxed) {
                        self.execute_steps::<false>(started);
                        ran += 1;
                    }
                    if ran > 1 {
                        ended = self.clock.now();
                    }
                    let took = ended.saturating_sub(started);
                    self.stats.record_cycles(ran, took);
                    done += ran;
                    size = next_batch(size, ran, took);
                    self.changes.apply_pending(&mut self.steps);
                }
            }
            Trigger::Data(wakeup) => {
                while more(done) {
                    // Wake now and then to see the stop flag even without data; a
                    // wakeup that comes with a stop request (a nudge) runs no cycle.
                    let woken = wakeup.wait_in(self.wait, stop, Duration::from_millis(50));
                    session.boundary();
                    if woken && more(done) {
                        self.run_cycle();
                        done += 1;
                    }
                    self.changes.apply_pending(&mut self.steps);
                }
            }
        }
    }

    /// Starts the container on its own thread (with [`WaitMode::Inline`], a
    /// data-triggered container runs its cycles on the threads that deliver its data;
    /// its own thread only sleeps, unplaced, until the run ends: `inline.rs`).
    pub fn spawn(
        mut self,
        options: ThreadOptions,
        stop: Arc<AtomicBool>,
        limit: Option<u64>,
    ) -> std::io::Result<RunningContainer> {
        if let (WaitMode::Inline, Trigger::Data(wakeup)) = (options.wait, &self.trigger) {
            // No thread of its own to place: it runs on the threads that deliver.
            let wakeup = Arc::clone(wakeup);
            return inline::spawn(self, wakeup, stop, limit);
        }
        let stats = self.stats();
        self.wait = options.wait;
        let wakeup = match &self.trigger {
            Trigger::Data(w) => Some(Arc::clone(w)),
            Trigger::Periodic(_) | Trigger::Continuous => None,
        };
        let (warn_tx, warn_rx) = std::sync::mpsc::channel();
        let thread_name: String = stats.name.chars().take(15).collect();
        let join = std::thread::Builder::new()
            .name(thread_name)
            .spawn(move || {
                for warning in os::place_current_thread(&options) {
                    let _ = warn_tx.send(warning);
                }
                drop(warn_tx);
                ferroc_ports::stopping::watch(Arc::clone(&stop));
                self.run(&stop, limit);
            })?;
        let refusals: Vec<Refusal> = warn_rx.iter().collect();
        Ok(RunningContainer {
            stats,
            join,
            wakeup,
            warnings: refusals.iter().map(Refusal::line).collect(),
            refusals,
            ends_run: true,
        })
    }
}

/// A container running on its thread.
pub struct RunningContainer {
    /// Its statistics.
    pub stats: Arc<ContainerStats>,
    /// What the operating system refused of the [`ThreadOptions`], as warnings.
    pub warnings: Vec<String>,
    /// The same refusals, to be summarised over containers.
    pub refusals: Vec<Refusal>,
    join: std::thread::JoinHandle<()>,
    wakeup: Option<Arc<Wakeup>>,
    /// Whether the run is over once this container has ended (see
    /// `builder::cycles_of`); the others are stopped then.
    #[doc(hidden)]
    pub ends_run: bool,
}

impl RunningContainer {
    /// A thread that runs containers itself (the lockstep driver), reported as one.
    #[doc(hidden)]
    pub fn driver(stats: Arc<ContainerStats>, join: std::thread::JoinHandle<()>) -> Self {
        RunningContainer {
            stats,
            warnings: Vec::new(),
            refusals: Vec::new(),
            join,
            wakeup: None,
            ends_run: true,
        }
    }

    /// Wakes the container so that it sees a stop flag set by the caller: a
    /// data-triggered one waiting for data, a periodic one sleeping until its next
    /// deadline (which may be a long period away).
    pub fn nudge(&self) {
        if let Some(w) = &self.wakeup {
            ferroc_ports::port::Notify::notify(&**w);
        }
        self.join.thread().unpark();
    }

    /// Whether it runs when data arrives (rather than by the clock).
    pub fn is_data_triggered(&self) -> bool {
        self.wakeup.is_some()
    }

    /// Whether the thread has ended (cycle limit reached, or stopped).
    pub fn is_finished(&self) -> bool {
        self.join.is_finished()
    }

    /// Waits for the thread to end.
    pub fn join(self) {
        let _ = self.join.join();
    }
}

/// What the stats report of the step `name` that stopped with `payload` (a panic, or
/// [`StopStep`]).
fn stopped_note(name: &str, payload: &(dyn std::any::Any + Send)) -> String {
    if let Some(StopStep(why)) = payload.downcast_ref::<StopStep>() {
        return format!("`{name}` was stopped: {why}; the other steps keep running");
    }
    let why = payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a non-text panic payload".into());
    format!("`{name}` panicked: {why}; this step is stopped, the others keep running")
}

#[cfg(test)]
mod tests;
