//! What a run knows about its reproducibility: the run seed every module's
//! [`Random`](crate::Random) is derived from, and which modules read what breaks it
//! (the wall clock, the OS's randomness) through the runtime's APIs.
//!
//! A lockstep run promises the same output on every run. A module that reads the wall
//! clock ([`WallClock`]) or seeds from the OS ([`Setup::os_random`](crate::Setup::os_random))
//! breaks that promise; the runtime cannot stop it, but it says so: when the run is in
//! lockstep, each such module is named once, with what it read, as a run-time warning.
//! Reads before the run starts (in `create`) are kept and reported when a lockstep run
//! starts; reads after, at once.

use ferroc_ports::time::Timestamp;
use std::cell::Cell;
use std::sync::{Arc, Mutex};

/// What a module read that makes a run differ from the next.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Nondeterminism {
    /// The wall clock ([`WallClock::now`]).
    WallClock,
    /// The operating system's randomness ([`Setup::os_random`](crate::Setup::os_random)).
    OsRandom,
}

impl Nondeterminism {
    fn what(self) -> &'static str {
        match self {
            Nondeterminism::WallClock => "reads the wall clock",
            Nondeterminism::OsRandom => "seeds from the operating system's randomness",
        }
    }

    fn help(self) -> &'static str {
        match self {
            Nondeterminism::WallClock => {
                "take `Timestamp::now()` instead, which is model time in lockstep"
            }
            Nondeterminism::OsRandom => {
                "take `Setup::random()` instead, which is derived from the run seed (--seed)"
            }
        }
    }
}

/// The run seed and the reads that break reproducibility, shared by a Builder and the
/// handles of its modules.
#[derive(Debug)]
pub struct Determinism {
    seed: u64,
    state: Mutex<State>,
}

#[derive(Debug, Default)]
struct State {
    lockstep: bool,
    /// Each module once: its path and its first read.
    reads: Vec<(String, Nondeterminism)>,
}

impl Determinism {
    /// A run with this seed.
    pub fn new(seed: u64) -> Arc<Self> {
        Arc::new(Determinism {
            seed,
            state: Mutex::default(),
        })
    }

    /// The run seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// The run is in lockstep from now on: reports what was read so far, and every
    /// later read at once.
    #[doc(hidden)]
    pub fn start_lockstep(&self) {
        let mut state = self.lock();
        state.lockstep = true;
        for (path, what) in &state.reads {
            report(path, *what);
        }
    }

    /// The modules that read what breaks reproducibility, each once with its first
    /// read, in the order they did.
    pub fn reads(&self) -> Vec<(String, Nondeterminism)> {
        self.lock().reads.clone()
    }

    /// `path` read `what`: kept (once per module) and reported when in lockstep.
    pub(crate) fn note(&self, path: &str, what: Nondeterminism) {
        let mut state = self.lock();
        if state.reads.iter().any(|(p, _)| p == path) {
            return;
        }
        state.reads.push((path.to_owned(), what));
        if state.lockstep {
            report(path, what);
        }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|p| p.into_inner())
    }
}

fn report(path: &str, what: Nondeterminism) {
    ferroc_ports::console::report(&format!(
        "warning: `{path}` {}: this lockstep run will differ from the next; help: {}",
        what.what(),
        what.help()
    ));
}

/// The wall clock, for a module that needs the real time even in lockstep (a log
/// stamp, a deadline towards hardware). In lockstep its first read is reported: use
/// [`Timestamp::now`] for anything that decides what the module publishes.
#[derive(Debug)]
pub struct WallClock {
    path: String,
    run: Arc<Determinism>,
    read: Cell<bool>,
}

impl WallClock {
    pub(crate) fn new(path: &str, run: Arc<Determinism>) -> Self {
        WallClock {
            path: path.to_owned(),
            run,
            read: Cell::new(false),
        }
    }

    /// The system's time now, also in lockstep.
    pub fn now(&self) -> Timestamp {
        if !self.read.replace(true) {
            self.run.note(&self.path, Nondeterminism::WallClock);
        }
        Timestamp::from_system_time(std::time::SystemTime::now())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_module_is_kept_once_with_its_first_read() {
        let run = Determinism::new(5);
        let clock = WallClock::new("a/clock", Arc::clone(&run));
        clock.now();
        clock.now();
        run.note("a/clock", Nondeterminism::OsRandom);
        run.note("b/noise", Nondeterminism::OsRandom);
        run.start_lockstep();
        run.note("b/noise", Nondeterminism::OsRandom);
        assert_eq!(
            run.reads(),
            [
                ("a/clock".to_owned(), Nondeterminism::WallClock),
                ("b/noise".to_owned(), Nondeterminism::OsRandom)
            ]
        );
        assert_eq!(run.seed(), 5);
    }
}
