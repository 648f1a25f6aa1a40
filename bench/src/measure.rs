//! Timing child processes: wall time, exit code and peak RSS of exactly that child.
//!
//! `std::process::Child::wait` discards the child's resource usage, and
//! `getrusage(RUSAGE_CHILDREN)` reports the maximum over *all* children reaped so far
//! (so a big xmllint run would hide a small ferroc run). `wait4` gives the usage of the
//! one child it reaps, which is why this module calls it through `libc`.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// One run of a child process.
#[derive(Clone, Copy, Debug)]
pub struct Run {
    pub wall: Duration,
    /// Exit code; `None` when the child was killed by a signal.
    pub code: Option<i32>,
    /// Peak resident set size in bytes.
    pub peak_rss: u64,
    /// CPU time of the child (user + system): on a shared machine the wall time includes
    /// waiting for a core, the CPU time does not.
    pub cpu: Duration,
}

/// Runs `cmd` once with stdout and stderr sent to `log`, and reaps it with `wait4`.
pub fn run_once(cmd: &mut Command, log: &Path) -> std::io::Result<Run> {
    let out = std::fs::File::create(log)?;
    let err = out.try_clone()?;
    cmd.stdin(Stdio::null()).stdout(out).stderr(err);
    let start = Instant::now();
    let child = cmd.spawn()?;
    reap(child, start)
}

/// Runs `cmd` once with its standard output captured (stderr goes to ours), and reaps
/// it with `wait4`: the run and everything the child printed on stdout.
pub fn run_capture(cmd: &mut Command) -> std::io::Result<(Run, String)> {
    cmd.stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit());
    let start = Instant::now();
    let mut child = cmd.spawn()?;
    let mut out = String::new();
    if let Some(mut stdout) = child.stdout.take() {
        // Read to the end (the child closes it when it exits), then reap it.
        std::io::Read::read_to_string(&mut stdout, &mut out)?;
    }
    Ok((reap(child, start)?, out))
}

/// Waits for `child` with `wait4`, which also gives its resource usage.
fn reap(child: std::process::Child, start: Instant) -> std::io::Result<Run> {
    let pid = child.id() as libc::pid_t;
    let mut status: libc::c_int = 0;
    // SAFETY: an all-zero rusage is a valid value of this plain C struct.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    loop {
        // SAFETY: `pid` is our own unreaped child; both pointers are valid for writes.
        let r = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
        if r == pid {
            break;
        }
        let e = std::io::Error::last_os_error();
        if e.kind() != std::io::ErrorKind::Interrupted {
            return Err(e);
        }
    }
    let wall = start.elapsed();
    // `child` was reaped above; dropping a `Child` neither waits nor kills.
    drop(child);
    let code = libc::WIFEXITED(status).then(|| libc::WEXITSTATUS(status));
    // Linux reports ru_maxrss in KiB.
    let peak_rss = (usage.ru_maxrss.max(0) as u64) * 1024;
    Ok(Run {
        wall,
        code,
        peak_rss,
        cpu: timeval(usage.ru_utime) + timeval(usage.ru_stime),
    })
}

fn timeval(t: libc::timeval) -> Duration {
    Duration::from_secs(t.tv_sec.max(0) as u64) + Duration::from_micros(t.tv_usec.max(0) as u64)
}

/// CPU time (user + system) this process has used so far, over all its threads.
pub fn process_cpu_time() -> Duration {
    // SAFETY: an all-zero rusage is a valid value of this plain C struct.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: RUSAGE_SELF with a pointer valid for writes; cannot fail on Linux.
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut usage) };
    timeval(usage.ru_utime) + timeval(usage.ru_stime)
}

/// Best (shortest) wall time, least CPU time and highest peak RSS over up to `max_runs`
/// runs; stops
/// early once the runs have taken `budget` in total (slow cases get fewer repeats).
/// Returns the first failing run (non-zero exit) as soon as it happens.
pub fn best_of(
    make: impl Fn() -> Command,
    log: &Path,
    max_runs: usize,
    budget: Duration,
) -> std::io::Result<Run> {
    let mut best: Option<Run> = None;
    let mut spent = Duration::ZERO;
    for _ in 0..max_runs.max(1) {
        let run = run_once(&mut make(), log)?;
        if run.code != Some(0) {
            return Ok(run);
        }
        spent += run.wall;
        best = Some(match best {
            None => run,
            Some(b) => Run {
                wall: b.wall.min(run.wall),
                code: Some(0),
                peak_rss: b.peak_rss.max(run.peak_rss),
                cpu: b.cpu.min(run.cpu),
            },
        });
        if spent >= budget {
            break;
        }
    }
    Ok(best.expect("at least one run"))
}
