//! iB2C principle violations: the rules, the policies, and how reports reach the user
//! without flooding.
//!
//! Each behaviour instance owns a [`Monitor`] (its path, policy and rate-limit state)
//! and shares a [`ModuleViolations`] (one counter per rule) with the application's
//! [`ViolationLog`], which `ferroc run` drains for reports while it runs and reads for
//! the summary at the end. Nothing is formatted or allocated in a cycle without a report.

use std::collections::VecDeque;
use std::fmt::Write as _;
use std::sync::atomic::{AtomicU64, Ordering::Relaxed};
use std::sync::{Arc, Mutex, MutexGuard};

/// Every critical section here leaves its data consistent: ignore poisoning.
fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// What the behaviour base does when a principle is violated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ViolationPolicy {
    /// Report (rate-limited) and pass the values on unchanged.
    #[default]
    Warn,
    /// Report the first violation of each rule, count the rest, and correct the values
    /// (clamp into [0, 1], activity to the activation, derived activities to the
    /// activity, the goal-state activity to the last one).
    Clamp,
    /// Report and stop the module, as a panic does; the other modules keep running.
    Stop,
}

impl ViolationPolicy {
    /// The model spelling (`warn`, `clamp`, `stop`).
    pub fn as_str(self) -> &'static str {
        match self {
            ViolationPolicy::Warn => "warn",
            ViolationPolicy::Clamp => "clamp",
            ViolationPolicy::Stop => "stop",
        }
    }

    /// Parses the model spelling.
    pub fn parse(text: &str) -> Option<Self> {
        match text {
            "warn" => Some(ViolationPolicy::Warn),
            "clamp" => Some(ViolationPolicy::Clamp),
            "stop" => Some(ViolationPolicy::Stop),
            _ => None,
        }
    }
}

/// The runtime principles of iB2C (finroc.md §4.2 R1, R5, R6, R7).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Rule {
    /// Every meta signal (stimulation, inhibition, activity, target rating, derived
    /// activity) lies in [0, 1].
    Range,
    /// Activity ≤ activation.
    ActivityLimitation,
    /// Target rating 0 in two consecutive cycles with unchanged activation ⇒ activity
    /// unchanged, unless an activity input changed.
    GoalState,
    /// Every derived activity ≤ the activity.
    DerivedActivity,
}

impl Rule {
    /// Every rule, in report order.
    pub const ALL: [Rule; 4] = [
        Rule::Range,
        Rule::ActivityLimitation,
        Rule::GoalState,
        Rule::DerivedActivity,
    ];

    /// The rule's name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Rule::Range => "meta signal range",
            Rule::ActivityLimitation => "activity limitation",
            Rule::GoalState => "goal-state activity",
            Rule::DerivedActivity => "derived activity limitation",
        }
    }

    fn index(self) -> usize {
        self as usize
    }
}

/// How often a violation of one rule is reported under [`ViolationPolicy::Warn`]: at
/// most once per this many cycles of the module (FINROC's default for "Number Of Cycles
/// With Suppressed Warnings").
pub const WARN_EVERY_CYCLES: u64 = 250;

/// Reports kept for the reader at most; older ones are dropped (and counted).
const MAX_PENDING: usize = 1024;

/// The violation counters of one behaviour instance.
#[derive(Debug)]
pub struct ModuleViolations {
    /// The module's element path.
    pub path: String,
    /// Its policy.
    pub policy: ViolationPolicy,
    counts: [AtomicU64; 4],
}

impl ModuleViolations {
    /// How often `rule` was violated so far.
    pub fn count(&self, rule: Rule) -> u64 {
        self.counts[rule.index()].load(Relaxed)
    }
}

/// One line of the end-of-run summary.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ViolationCount {
    /// The module's element path.
    pub path: String,
    /// The violated rule.
    pub rule: Rule,
    /// The module's policy.
    pub policy: ViolationPolicy,
    /// How often it was violated.
    pub count: u64,
}

/// Every behaviour's counters and the reports not yet read, for one application.
#[derive(Debug, Default)]
pub struct ViolationLog {
    modules: Mutex<Vec<Arc<ModuleViolations>>>,
    pending: Mutex<VecDeque<String>>,
    dropped: AtomicU64,
}

impl ViolationLog {
    /// Registers a behaviour instance.
    pub(crate) fn register(&self, path: &str, policy: ViolationPolicy) -> Arc<ModuleViolations> {
        let m = Arc::new(ModuleViolations {
            path: path.to_owned(),
            policy,
            counts: Default::default(),
        });
        lock(&self.modules).push(Arc::clone(&m));
        m
    }

    fn push(&self, report: String) {
        let mut pending = lock(&self.pending);
        if pending.len() >= MAX_PENDING {
            pending.pop_front();
            self.dropped.fetch_add(1, Relaxed);
        }
        pending.push_back(report);
    }

    /// The reports since the last call, oldest first.
    pub fn take_reports(&self) -> Vec<String> {
        lock(&self.pending).drain(..).collect()
    }

    /// Reports dropped because nobody read them in time.
    pub fn dropped(&self) -> u64 {
        self.dropped.load(Relaxed)
    }

    /// Every (module, rule) violated at least once, by module path then rule.
    pub fn counts(&self) -> Vec<ViolationCount> {
        let mut out = Vec::new();
        for m in lock(&self.modules).iter() {
            for rule in Rule::ALL {
                let count = m.count(rule);
                if count > 0 {
                    out.push(ViolationCount {
                        path: m.path.clone(),
                        rule,
                        policy: m.policy,
                        count,
                    });
                }
            }
        }
        out.sort_by(|a, b| {
            a.path
                .cmp(&b.path)
                .then(a.rule.index().cmp(&b.rule.index()))
        });
        out
    }
}

/// What to do with a violating value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Action {
    /// Pass it on.
    Pass,
    /// Correct it.
    Correct,
}

/// The violation bookkeeping of one behaviour instance (owned by its step).
pub(crate) struct Monitor {
    policy: ViolationPolicy,
    shared: Arc<ModuleViolations>,
    log: Arc<ViolationLog>,
    cycle: u64,
    last_report: [Option<u64>; 4],
    unreported: [u64; 4],
    /// A violation under [`ViolationPolicy::Stop`]: the report that stops the module.
    pub stop: Option<String>,
}

impl Monitor {
    pub fn new(path: &str, policy: ViolationPolicy, log: Arc<ViolationLog>) -> Self {
        Monitor {
            policy,
            shared: log.register(path, policy),
            log,
            cycle: 0,
            last_report: [None; 4],
            unreported: [0; 4],
            stop: None,
        }
    }

    /// Starts a new cycle.
    pub fn next_cycle(&mut self) {
        self.cycle += 1;
    }

    /// Records a violation of `rule`; `describe` writes what happened (the values) and
    /// is called only when a report is made.
    pub fn violated(&mut self, rule: Rule, describe: impl FnOnce(&mut String)) -> Action {
        let i = rule.index();
        self.shared.counts[i].fetch_add(1, Relaxed);
        let report = match self.policy {
            ViolationPolicy::Stop => self.stop.is_none(),
            ViolationPolicy::Clamp => self.last_report[i].is_none(),
            ViolationPolicy::Warn => self.last_report[i]
                .is_none_or(|last| self.cycle.saturating_sub(last) >= WARN_EVERY_CYCLES),
        };
        if !report {
            self.unreported[i] += 1;
            return self.action();
        }
        let mut text = format!(
            "iB2C principle violation in `{}` ({}): ",
            self.shared.path,
            rule.name()
        );
        describe(&mut text);
        match self.policy {
            ViolationPolicy::Warn => text.push_str("; passed on unchanged"),
            ViolationPolicy::Clamp => text.push_str(
                "; corrected (policy clamp: further violations of this rule are counted, not reported)",
            ),
            ViolationPolicy::Stop => text.push_str("; the module is stopped (policy stop)"),
        }
        if self.unreported[i] > 0 {
            let _ = write!(text, " [{} more since the last report]", self.unreported[i]);
        }
        self.unreported[i] = 0;
        self.last_report[i] = Some(self.cycle);
        if self.policy == ViolationPolicy::Stop {
            self.stop = Some(text);
        } else {
            self.log.push(text);
        }
        self.action()
    }

    fn action(&self) -> Action {
        match self.policy {
            ViolationPolicy::Warn => Action::Pass,
            ViolationPolicy::Clamp | ViolationPolicy::Stop => Action::Correct,
        }
    }
}
