//! What a run's summary says, as data: [`supervise_summarised`](super::supervise_summarised)
//! gives it alongside the exit code, and `ferroc run --format json` prints it (the
//! shape is documented in docs/run-summary.md).

use crate::builder::RunningApp;
use serde::Serialize;

/// The end of a run: why it stopped, each thread container's figures, the iB2C
/// violations counted, what went wrong, the data lost and the exit code.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Summary {
    /// Why the run stopped: `cycle limit reached`, `time is up`, `model time is up`
    /// (lockstep `--for`), `interrupted`, `failed`.
    pub reason: String,
    /// Wall-clock seconds from the start of supervision to the stop.
    pub seconds: f64,
    /// Every thread container, in the order the status line shows them.
    pub containers: Vec<ContainerFigures>,
    /// How often each behaviour broke each iB2C rule.
    pub violations: Vec<Violations>,
    /// Violation reports dropped unread.
    pub violation_reports_dropped: u64,
    /// Modules that panicked (each message names the module).
    pub panics: Vec<String>,
    /// Thread containers that did not stop in time and were left behind.
    pub stuck: Vec<String>,
    /// Why the application failed (a lockstep driver's error), if it did.
    pub failure: Option<String>,
    /// The data modules reported lost (a recording cut short): exit code 3.
    pub data_lost: Vec<String>,
    /// The process's exit code: 0, 1 (a panic, a stuck container, a failure) or 3.
    pub exit_code: u8,
}

/// One thread container's figures at the end of a run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ContainerFigures {
    /// Element path.
    pub path: String,
    /// Cycles completed.
    pub cycles: u64,
    /// Cycles that missed their deadline.
    pub overruns: u64,
    /// Average share of the period spent executing (0 to 1; 0 when data-triggered).
    pub load: f64,
}

/// One behaviour's count of one rule's violations.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Violations {
    /// The module's element path.
    pub path: String,
    /// The rule's name.
    pub rule: String,
    /// How often.
    pub count: u64,
    /// The module's policy.
    pub policy: String,
}

impl Summary {
    /// The figures of `app` after it stopped; `exit_code` is filled in by the caller.
    pub(super) fn of(app: &RunningApp, reason: &str, seconds: f64, stuck: &[String]) -> Summary {
        Summary {
            reason: reason.to_owned(),
            seconds,
            containers: (app.status().into_iter())
                .map(|s| ContainerFigures {
                    path: s.path,
                    cycles: s.cycles,
                    overruns: s.overruns,
                    load: s.load,
                })
                .collect(),
            violations: (app.violation_counts().into_iter())
                .map(|v| Violations {
                    path: v.path,
                    rule: v.rule.name().to_owned(),
                    count: v.count,
                    policy: v.policy.as_str().to_owned(),
                })
                .collect(),
            violation_reports_dropped: app.violation_reports_dropped(),
            panics: app.panics(),
            stuck: stuck.to_vec(),
            failure: app.failure().map(str::to_owned),
            data_lost: ferroc_module::data_losses(),
            exit_code: 0,
        }
    }
}
