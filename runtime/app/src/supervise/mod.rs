//! Supervising a started application: one piece of code for `ferroc run` and for the
//! programs `ferroc bundle` generates, so both behave and report alike.
//!
//! [`supervise`] waits until the cycle limit, a time limit or an interruption (Ctrl-C,
//! SIGTERM: the caller's signal handler sets a flag), draws a live status line on a
//! terminal, reports module panics and lock-order problems as they happen, stops cleanly and prints a summary
//! (reason, run time, cycles, overruns and load per thread container) on standard error.
//!
//! [`Args`] is the small command line of a generated program (`--cycles N`, `--for 10s`,
//! `--quiet`, `--help`), parsed without a dependency.

mod args;
mod summary;

use crate::builder::RunningApp;
pub use args::{parse_duration, parse_seed, run_seed, Args};
use ferroc_ports::console::escape;
use std::io::Write;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};
pub use summary::{ContainerFigures, Summary, Violations};

/// How [`supervise`] runs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Options {
    /// Stop after this long (`None`: until the cycle limit or an interruption).
    pub duration: Option<Duration>,
    /// Draw a live status line on standard error (only sensible on a terminal).
    pub status_line: bool,
}

/// Runs `app` until every container reached its cycle limit, `options.duration` passed
/// or `interrupted` is set; prints the operating system's warnings first, panics as they
/// happen and a summary at the end. Exit code 1 if a module panicked or a container
/// did not stop within a few seconds of being asked (it is left behind), else 3
/// ([`DATA_LOST`]) if a module reported data lost (a recording cut short), else 0.
pub fn supervise(app: RunningApp, interrupted: &AtomicBool, options: &Options) -> ExitCode {
    supervise_summarised(app, interrupted, options).0
}

/// [`supervise`], also giving the summary it printed as data (`ferroc run --format
/// json`).
pub fn supervise_summarised(
    mut app: RunningApp,
    interrupted: &AtomicBool,
    options: &Options,
) -> (ExitCode, Summary) {
    for w in app.warnings() {
        eprintln!("warning: {}", escape(w));
    }
    let status = options.status_line;
    ferroc_ports::console::set_status_line_active(status);
    let started = Instant::now();
    let (reason, reported) = watch(&app, interrupted, options, started);
    app.stop();
    let stuck = app.join_within(STOP_GRACE);
    ferroc_ports::console::set_status_line_active(false);
    if status {
        eprint!("\r\x1b[K");
    }
    let panicked = report_the_end(&app, &stuck, reported);
    let mut summary = Summary::of(&app, reason, started.elapsed().as_secs_f64(), &stuck);
    print_summary(&summary);
    report_losses(&summary.data_lost);
    summary.exit_code = if panicked || !stuck.is_empty() || app.failure().is_some() {
        1
    } else if !summary.data_lost.is_empty() {
        DATA_LOST
    } else {
        0
    };
    (ExitCode::from(summary.exit_code), summary)
}

/// The exit code of a run that ended without errors but lost data it was meant to
/// keep (a recording cut short): a script sees that the run is not whole.
pub const DATA_LOST: u8 = 3;

/// The end of the summary: the data modules reported lost
/// ([`ferroc_module::report_data_loss`]).
fn report_losses(lost: &[String]) {
    if !lost.is_empty() {
        eprintln!("data lost (exit code {DATA_LOST}):");
        for l in lost {
            eprintln!("  {}", escape(l));
        }
    }
}

/// How many panics and lock reports the user has seen while the application ran.
#[derive(Clone, Copy, Default)]
struct Reported {
    panics: usize,
    locks: usize,
}

/// While the application runs: reports panics, lock-order inversions, iB2C
/// violations and network trouble as they come and redraws the status line, until
/// the application ends, `interrupted` is set or the time is up. Gives why it stopped.
fn watch(
    app: &RunningApp,
    interrupted: &AtomicBool,
    options: &Options,
    started: Instant,
) -> (&'static str, Reported) {
    let mut last_draw = Instant::now() - Duration::from_secs(1);
    let mut reported = Reported::default();
    let mut network_log = NetworkLog::default();
    let reason = loop {
        if app.is_finished() {
            break app.end_reason();
        }
        if interrupted.load(Ordering::SeqCst) {
            break "interrupted";
        }
        if options.duration.is_some_and(|d| started.elapsed() >= d) {
            break "time is up";
        }
        let panics = app.panics();
        for p in &panics[reported.panics..] {
            ferroc_ports::console::report(&format!("error: {p}"));
        }
        reported.panics = panics.len();
        let locks = app.lock_reports();
        for l in &locks[reported.locks..] {
            ferroc_ports::console::report(&format!("warning: {l}"));
        }
        reported.locks = locks.len();
        report_violations(app);
        let network = app.network_status();
        if network_log.due(!network.is_empty(), Instant::now()) {
            for line in &network {
                ferroc_ports::console::note(&format!("warning: {line}"));
            }
        }
        if options.status_line && last_draw.elapsed() >= Duration::from_millis(250) {
            last_draw = Instant::now();
            let line = status_line(app, &network, started.elapsed());
            let _ = write!(std::io::stderr(), "\r\x1b[K{line}");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    (reason, reported)
}

/// After the stop: the containers left behind, and the violations, panics and lock
/// reports not shown yet. Gives whether any module panicked.
fn report_the_end(app: &RunningApp, stuck: &[String], reported: Reported) -> bool {
    for path in stuck {
        eprintln!(
            "error: thread container `{path}` did not stop within {} s: one of its steps \
             is still running (looping, or waiting outside the ports); exiting without it",
            STOP_GRACE.as_secs()
        );
    }
    report_violations(app);
    let panics = app.panics();
    for p in &panics[reported.panics.min(panics.len())..] {
        eprintln!("error: {}", escape(p));
    }
    let locks = app.lock_reports();
    for l in &locks[reported.locks.min(locks.len())..] {
        eprintln!("warning: {}", escape(l));
    }
    !panics.is_empty()
}

/// The summary: why and when the run stopped, each container's figures, the iB2C
/// violations counted.
fn print_summary(summary: &Summary) {
    eprintln!(
        "stopped ({}) after {:.1} s",
        summary.reason, summary.seconds
    );
    for s in &summary.containers {
        eprintln!(
            "  {}: {} cycles, {} overruns, load {:.1} %",
            s.path,
            s.cycles,
            s.overruns,
            s.load * 100.0
        );
    }
    if !summary.violations.is_empty() {
        eprintln!("iB2C principle violations:");
        for v in &summary.violations {
            eprintln!(
                "  {}: {} × {} (policy {})",
                v.path, v.count, v.rule, v.policy
            );
        }
        let dropped = summary.violation_reports_dropped;
        if dropped > 0 {
            eprintln!("  ({dropped} reports were dropped unread)");
        }
    }
}

/// How long a stopped application may take to finish its current cycles. Containers
/// stop after the cycle they are in (a sleeping one at once, a write blocked on a full
/// queue within 100 ms); a step that takes longer than this is left behind.
const STOP_GRACE: Duration = Duration::from_secs(3);

/// How often the log repeats what the network reports while it lasts (a part gone
/// since …): the network notes the loss itself when it happens.
const NETWORK_LOG_EVERY: Duration = Duration::from_secs(5);

/// When to repeat the network's report in the log.
#[derive(Default)]
struct NetworkLog {
    /// Since when something is reported (or it was last logged).
    since: Option<Instant>,
}

impl NetworkLog {
    /// Whether to log the network's report at `now`, given whether it has anything.
    fn due(&mut self, reporting: bool, now: Instant) -> bool {
        match (reporting, self.since) {
            (false, _) => {
                self.since = None;
                false
            }
            (true, None) => {
                self.since = Some(now);
                false
            }
            (true, Some(t)) if now.duration_since(t) >= NETWORK_LOG_EVERY => {
                self.since = Some(now);
                true
            }
            (true, Some(_)) => false,
        }
    }
}

fn status_line(app: &RunningApp, network: &[String], elapsed: Duration) -> String {
    status_text(&app.status(), network, elapsed)
}

fn status_text(
    containers: &[crate::builder::ContainerStatus],
    network: &[String],
    elapsed: Duration,
) -> String {
    let mut line = format!("{:>6.1} s", elapsed.as_secs_f64());
    for n in network {
        line.push_str(&format!(" | {}", escape(n)));
    }
    for s in containers {
        let name = s.path.rsplit('/').next().unwrap_or(&s.path);
        line.push_str(&format!(
            " | {name}: {} cycles, {} overruns, load {:.0} %",
            s.cycles,
            s.overruns,
            s.load * 100.0
        ));
    }
    line
}

/// Prints the iB2C violation reports made since the last call (each already
/// rate-limited by its module's policy).
fn report_violations(app: &RunningApp) {
    for r in app.take_violation_reports() {
        ferroc_ports::console::report(&format!("warning: {r}"));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_status_line_shows_a_part_that_is_gone_and_the_log_repeats_it() {
        let containers = [crate::builder::ContainerStatus {
            path: "station/ui".into(),
            cycles: 12,
            overruns: 0,
            load: 0.25,
        }];
        let gone = ["link robot → station: part robot gone since 3.2 s".to_string()];
        let line = status_text(&containers, &gone, Duration::from_millis(7500));
        assert_eq!(
            line,
            "   7.5 s | link robot → station: part robot gone since 3.2 s | ui: 12 cycles, \
             0 overruns, load 25 %"
        );
        assert!(!status_text(&containers, &[], Duration::ZERO).contains("gone"));
        // The log: not at the loss (the network notes it then), every 5 s while it
        // lasts, and from the start again after the part came back.
        let mut log = NetworkLog::default();
        let t0 = Instant::now();
        let at = |ms: u64| t0 + Duration::from_millis(ms);
        assert!(!log.due(false, at(0)));
        assert!(
            !log.due(true, at(100)),
            "the loss itself is noted elsewhere"
        );
        assert!(!log.due(true, at(5_000)));
        assert!(log.due(true, at(5_100)));
        assert!(!log.due(true, at(9_000)));
        assert!(log.due(true, at(10_100)));
        assert!(!log.due(false, at(10_200)), "back");
        assert!(!log.due(true, at(10_300)), "gone again: a new loss");
        assert!(!log.due(true, at(15_299)));
        assert!(log.due(true, at(15_300)));
    }
}
