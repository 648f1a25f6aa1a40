//! Checks run off the main loop, on one thread of their own: a request that finds the
//! worker idle is checked at once (a keystroke after a pause waits for nothing but its
//! check); requests that arrive while a check runs are debounced (a burst of
//! keystrokes is one check), merged (the newest texts win, the models to check add
//! up), and a result that is already stale when it is ready — a newer
//! request for the same model is waiting — is dropped instead of published. A check
//! that is running is not interrupted (the compiler has no cancellation point); at
//! most one stale check runs to its end before the newest text is checked.

use crossbeam_channel::{Receiver, RecvTimeoutError, Sender};
use ferroc_compiler::load::{Options, Overlay, ParseCache};
use ferroc_compiler::{check_model, CheckResult, Policy};
use std::collections::BTreeSet;
use std::panic::AssertUnwindSafe;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// How long the worker waits for the typing to pause before it checks the changes that
/// arrived while it was checking.
pub const DEBOUNCE: Duration = Duration::from_millis(50);

/// How long an idle worker gathers the changes that arrive together (a client sends a
/// paste or a multi-cursor edit as several notifications at once) before it checks.
pub const GATHER: Duration = Duration::from_millis(2);

/// Check these models with these texts.
pub struct Job {
    pub roots: BTreeSet<PathBuf>,
    pub overlay: Overlay,
}

/// One model checked.
pub struct Outcome {
    pub root: PathBuf,
    /// `Err`: the model could not be checked at all (unreadable, or the compiler
    /// failed), in words.
    pub result: Result<Arc<CheckResult>, String>,
    pub took: Duration,
    /// The CPU time the check took on its thread (Linux), which unlike `took` does not
    /// grow with the machine's load.
    pub cpu: Option<Duration>,
}

/// The CPU time this thread has run (Linux: `/proc/thread-self/schedstat`, in ns).
pub fn thread_cpu() -> Option<Duration> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: u64 = text.split_whitespace().next()?.parse().ok()?;
    Some(Duration::from_nanos(ns))
}

/// Starts the worker; it ends when the job sender is dropped. Its checks keep the
/// files' syntax trees between them (`Options::cache`): a keystroke re-parses the
/// element it changed, not the file.
pub fn start(mut options: Options, jobs: Receiver<Job>, done: Sender<Outcome>) {
    options.cache = Some(Arc::new(ParseCache::default()));
    std::thread::Builder::new()
        .name("ferroc-lsp-check".into())
        .spawn(move || run(&options, &jobs, &done))
        .expect("the check thread starts");
}

fn run(options: &Options, jobs: &Receiver<Job>, done: &Sender<Outcome>) {
    let Ok(mut job) = jobs.recv() else { return };
    // The worker was idle: the first change of a pause is checked at once.
    let mut pause = GATHER;
    loop {
        // Debounce: wait until no request came for `pause`.
        loop {
            match jobs.recv_timeout(pause) {
                Ok(next) => merge(&mut job, next),
                Err(RecvTimeoutError::Timeout) => break,
                Err(RecvTimeoutError::Disconnected) => return,
            }
        }
        match check_roots(options, &mut job, jobs, done) {
            Next::Idle => match jobs.recv() {
                Ok(next) => {
                    job = next;
                    pause = GATHER;
                }
                Err(_) => return,
            },
            // Changes came in during the check: the user is typing.
            Next::Again => pause = DEBOUNCE,
            Next::Stop => return,
        }
    }
}

enum Next {
    Idle,
    Again,
    Stop,
}

/// Checks the job's models one by one; a newer request that arrives in between is
/// merged in and the round starts again (after its own debounce).
fn check_roots(
    options: &Options,
    job: &mut Job,
    jobs: &Receiver<Job>,
    done: &Sender<Outcome>,
) -> Next {
    while let Some(root) = job.roots.pop_first() {
        let mut opts = options.clone();
        opts.overlay = job.overlay.clone();
        let start = Instant::now();
        let cpu_start = thread_cpu();
        let result = check_one(&root, &opts);
        let took = start.elapsed();
        let cpu = thread_cpu()
            .zip(cpu_start)
            .map(|(b, a)| b.saturating_sub(a));
        let (mut stale, mut merged) = (false, false);
        while let Ok(next) = jobs.try_recv() {
            stale |= next.roots.contains(&root);
            merged = true;
            merge(job, next);
        }
        if !stale {
            let outcome = Outcome {
                root,
                result,
                took,
                cpu,
            };
            if done.send(outcome).is_err() {
                return Next::Stop;
            }
        }
        if merged {
            return Next::Again;
        }
    }
    Next::Idle
}

/// One model through the compiler; a panic in the compiler becomes an error in words
/// (the server goes on).
fn check_one(root: &std::path::Path, options: &Options) -> Result<Arc<CheckResult>, String> {
    let policy = Policy::default();
    match std::panic::catch_unwind(AssertUnwindSafe(|| check_model(root, options, &policy))) {
        Ok(Ok(result)) => Ok(Arc::new(result)),
        Ok(Err(e)) => Err(e),
        Err(_) => Err(format!(
            "the compiler failed on {} (an internal error; please report it with the file)",
            root.display()
        )),
    }
}

fn merge(job: &mut Job, next: Job) {
    job.roots.extend(next.roots);
    job.overlay = next.overlay;
}
