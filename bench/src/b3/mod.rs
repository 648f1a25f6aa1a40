//! B3 — image fan-out (FINROC's Table 2): one producer, 1 / 7 / 15 consumers.
//!
//! The producer is a periodic thread container (20 ms, so 50 fps) whose step fills a
//! buffer of its output port with a memcpy of a 1920×1080 RGB24 source frame
//! (6,220,800 bytes) and publishes it. Every consumer is a data-triggered thread
//! container of its own with one latest-value input connected to that output; its step
//! takes the frame (a [`PortRef`](ferroc_runtime::port::PortRef): zero-copy, the same
//! buffer for every consumer), reads one byte of it, counts it, and drops the reference
//! at once so the buffer can go back to the pool.
//!
//! Pool size: the port's pool grows only when every buffer is held at a publish. Each
//! latest-value input keeps the newest frame (one buffer, shared by all inputs), and a
//! consumer holds it only for the microseconds of its step, so the producer always
//! finds the previous frame's buffer free: 2 buffers in steady state, whatever the
//! consumer count (reported as `buffers`). The port's initial value is a third, never
//! written `vec![0; N]` whose pages are never touched, so it is not resident.
//!
//! Each configuration runs in a child process of this benchmark (the same executable,
//! re-run with a hidden argument), so that its peak RSS (`ru_maxrss` from `wait4`) is
//! its own and not the maximum over everything measured before. The child measures a
//! window after 0.5 s of warm-up: frames each consumer saw (rate between the first and
//! the last frame in the window; sequence gaps are `missed`), and the CPU time of the
//! whole process (`getrusage(RUSAGE_SELF)`, user + system) over the window's wall time,
//! 100 % = one core busy. `--seconds` per configuration are split into `--rounds` child
//! runs, interleaved over the configurations so that a noisy moment of a shared machine
//! does not land on one configuration alone; rates and CPU are averaged over the
//! measured time, peak RSS is the highest.
//!
//! Baseline, in the same run: the same periodic container and memcpy into a plain
//! `Vec<u8>`, no ports, no consumers. Two diagnostics split the cost of a consumer: the
//! baseline plus 15 data-triggered containers woken through their [`Wakeup`] without
//! ports or images, and the baseline plus 15 plain threads woken with
//! `Thread::unpark`, without the runtime.

use crate::measure::{self, process_cpu_time};
use crate::options::Options;
use ferroc_runtime::container::{RunningContainer, Step, ThreadContainer, ThreadOptions, Trigger};
use ferroc_runtime::port::{
    connect, ConnectOptions, InputPort, Notifier, Notify, OutputPort, Wakeup,
};
use std::collections::HashMap;
use std::process::Command;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// 1920 × 1080 pixels × 3 bytes (RGB24).
pub const FRAME_BYTES: usize = 1920 * 1080 * 3;
/// 50 fps.
const PERIOD: Duration = Duration::from_millis(20);
/// Consumer counts measured; the last one is the RESULT line.
const CONSUMERS: [usize; 3] = [1, 7, LAST];
const LAST: usize = 15;
/// Not measured: threads start, pages of the buffers are touched for the first time.
const WARM_UP: Duration = Duration::from_millis(500);
/// The hidden first argument that makes this executable a B3 configuration.
pub const CHILD_ARG: &str = "__b3-child";
const DEFAULT_SECONDS: f64 = 5.0;
const DEFAULT_ROUNDS: u32 = 2;

/// A published image: the frame number (to spot dropped frames) and the pixels.
#[derive(Default)]
struct Image {
    seq: u64,
    data: Vec<u8>,
}

/// What one configuration reported (one `B3CHILD key=value ...` line), or several
/// runs of it merged.
#[derive(Clone, Copy)]
struct Figures {
    mode: Mode,
    /// Measured wall time.
    window_s: f64,
    fps_mean: f64,
    fps_min: f64,
    missed: u64,
    producer_fps: f64,
    overruns: u64,
    cpu_pct: f64,
    buffers: u64,
    rss_mib: f64,
}

impl Figures {
    /// Both runs as one: rates and CPU weighted by measured time, extremes kept.
    fn merge(self, o: Figures) -> Figures {
        let w = self.window_s + o.window_s;
        let avg = |a: f64, b: f64| (a * self.window_s + b * o.window_s) / w;
        Figures {
            mode: self.mode,
            window_s: w,
            fps_mean: avg(self.fps_mean, o.fps_mean),
            fps_min: self.fps_min.min(o.fps_min),
            missed: self.missed + o.missed,
            producer_fps: avg(self.producer_fps, o.producer_fps),
            overruns: self.overruns + o.overruns,
            cpu_pct: avg(self.cpu_pct, o.cpu_pct),
            buffers: self.buffers.max(o.buffers),
            rss_mib: self.rss_mib.max(o.rss_mib),
        }
    }
}

/// Runs B3 and prints its lines. Returns the process exit code.
pub fn run(args: &[String]) -> u8 {
    let parsed = Options::parse("b3", args, &["seconds", "rounds"], &[]).and_then(|o| {
        Ok((
            o.number("seconds", DEFAULT_SECONDS, 0.2, 600.0)?,
            o.number("rounds", DEFAULT_ROUNDS, 1, 100)?,
        ))
    });
    let (seconds, rounds) = match parsed {
        Ok((s, r)) if s / f64::from(r) >= 0.2 => (s, r),
        Ok((s, r)) => {
            eprintln!("b3: --seconds {s} over --rounds {r} leaves less than 0.2 s per run");
            return 2;
        }
        Err(e) => {
            eprintln!("{e}");
            return 2;
        }
    };
    if cfg!(debug_assertions) {
        println!(
            "b3: warning: not a release build; figures are meaningless (use cargo run --release)"
        );
    }
    let window = seconds / f64::from(rounds);
    println!(
        "b3: 1920x1080 RGB24 frames ({FRAME_BYTES} bytes) at 50 fps; {seconds} s measured per \
         configuration in {rounds} rounds (one child process each: {:.1} s warm-up + {window:.2} \
         s); {}",
        WARM_UP.as_secs_f64(),
        load_note()
    );
    let modes: Vec<Mode> = std::iter::once(Mode::Baseline)
        .chain(CONSUMERS.map(Mode::Ports))
        .chain([Mode::Wakeups(LAST), Mode::Threads(LAST)])
        .collect();
    let rows = match measure_rounds(&modes, rounds, window) {
        Ok(rows) => rows,
        Err(e) => {
            eprintln!("b3: {e}");
            return 1;
        }
    };
    for f in &rows {
        print_row(f);
    }
    print_findings(&rows);
    0
}

/// Every configuration in each of `rounds` rounds of `window` seconds, a line of CPU
/// figures per round; the figures of each configuration merged over the rounds.
fn measure_rounds(modes: &[Mode], rounds: u32, window: f64) -> Result<Vec<Figures>, String> {
    let mut merged: Vec<Option<Figures>> = vec![None; modes.len()];
    for round in 0..rounds as usize {
        let mut line = format!("b3 round {}: cpu %", round + 1);
        // Rotate the order, so that no configuration always runs first or last.
        for k in 0..modes.len() {
            let i = (round + k) % modes.len();
            let f = configuration(modes[i], window)?;
            line += &format!("  {} {:.2}", modes[i].arg(), f.cpu_pct);
            merged[i] = Some(merged[i].map_or(f, |m| m.merge(f)));
        }
        println!("{line}; {}", load_note());
    }
    Ok(merged.into_iter().flatten().collect())
}

/// What each further consumer costs, the targets at the most consumers, and the
/// `RESULT` line.
fn print_findings(rows: &[Figures]) {
    let [base, one, _, last, wakeups, threads] = rows else {
        unreachable!("six configurations")
    };
    let ratio_1 = last.cpu_pct / one.cpu_pct;
    let ratio_base = last.cpu_pct / base.cpu_pct;
    // CPU time per consumer and frame, in µs: what each further consumer costs.
    let per_frame_us = |extra_pct: f64, consumers: usize| {
        extra_pct / 100.0 / (consumers as f64 * 1e3 / PERIOD.as_millis() as f64) * 1e6
    };
    println!(
        "b3: CPU per consumer and frame: {:.1} µs with ports ({LAST} vs 1 consumer); over the \
         baseline, {:.1} µs for a container woken without ports, {:.1} µs for a plain thread \
         unparked without the runtime",
        per_frame_us(last.cpu_pct - one.cpu_pct, LAST - 1),
        per_frame_us(wakeups.cpu_pct - base.cpu_pct, LAST),
        per_frame_us(threads.cpu_pct - base.cpu_pct, LAST),
    );
    println!(
        "b3: at {LAST} consumers: fps {:.1} (target 50.0), CPU {ratio_1:.2}x of 1 consumer \
         (target <= 1.2x), {ratio_base:.2}x of the baseline (target <= 1.5x), peak RSS {:.1} MiB \
         (target <= 32 MiB); {}",
        last.fps_mean,
        last.rss_mib,
        load_note()
    );
    println!(
        "RESULT b3 consumers={LAST} fps={:.2} cpu_pct={:.2} cpu_ratio_vs_1={ratio_1:.2} \
         rss_mib={:.1} baseline_cpu_pct={:.2} cpu_ratio_vs_baseline={ratio_base:.2} \
         fps_min={:.2} missed={} buffers={} cpu_pct_1={:.2} baseline_rss_mib={:.1} \
         wakeups_only_cpu_pct={:.2} threads_only_cpu_pct={:.2}",
        last.fps_mean,
        last.cpu_pct,
        last.rss_mib,
        base.cpu_pct,
        last.fps_min,
        last.missed,
        last.buffers,
        one.cpu_pct,
        base.rss_mib,
        wakeups.cpu_pct,
        threads.cpu_pct,
    );
}

fn print_row(f: &Figures) {
    match f.mode {
        Mode::Baseline => println!(
            "b3 baseline: memcpy into a Vec, no ports      producer {:5.2} fps  cpu {:5.2} %  \
             peak RSS {:5.1} MiB  overruns {}",
            f.producer_fps, f.cpu_pct, f.rss_mib, f.overruns
        ),
        Mode::Ports(n) => println!(
            "b3 consumers={n:>2}  fps mean {:5.2} min {:5.2}  missed {}  producer {:5.2} fps  \
             cpu {:5.2} %  peak RSS {:5.1} MiB  pool {} buffers  overruns {}",
            f.fps_mean,
            f.fps_min,
            f.missed,
            f.producer_fps,
            f.cpu_pct,
            f.rss_mib,
            f.buffers,
            f.overruns
        ),
        Mode::Wakeups(n) => println!(
            "b3 diagnostic: baseline + {n} containers woken, no ports  fps mean {:5.2}  \
             missed {}  cpu {:5.2} %  peak RSS {:5.1} MiB",
            f.fps_mean, f.missed, f.cpu_pct, f.rss_mib
        ),
        Mode::Threads(n) => println!(
            "b3 diagnostic: baseline + {n} plain threads unparked, no runtime  fps mean {:5.2}  \
             missed {}  cpu {:5.2} %  peak RSS {:5.1} MiB",
            f.fps_mean, f.missed, f.cpu_pct, f.rss_mib
        ),
    }
}

/// The load average and core count, so a reader can judge the figures.
pub fn load_note() -> String {
    let load = std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next().map(str::to_string))
        .unwrap_or_else(|| "?".into());
    // Online CPUs of the machine (not this thread's affinity, which b4 --pin narrows).
    // SAFETY: sysconf only reads a system setting.
    let cores = unsafe { libc::sysconf(libc::_SC_NPROCESSORS_ONLN) };
    format!("load average {load} on {cores} cores")
}

/// Runs one configuration in a child process and reads its report.
fn configuration(mode: Mode, seconds: f64) -> Result<Figures, String> {
    let exe = std::env::current_exe().map_err(|e| format!("cannot find own executable: {e}"))?;
    let mut cmd = Command::new(&exe);
    cmd.arg(CHILD_ARG).arg(mode.arg()).arg(seconds.to_string());
    let (run, out) =
        measure::run_capture(&mut cmd).map_err(|e| format!("cannot run {}: {e}", exe.display()))?;
    if run.code != Some(0) {
        return Err(format!(
            "configuration {} failed (exit {:?}); output:\n{out}",
            mode.arg(),
            run.code
        ));
    }
    let line = out
        .lines()
        .find_map(|l| l.strip_prefix("B3CHILD "))
        .ok_or_else(|| format!("configuration {} printed no report:\n{out}", mode.arg()))?;
    let kv: HashMap<&str, &str> = line
        .split_whitespace()
        .filter_map(|p| p.split_once('='))
        .collect();
    let num = |k: &str| -> Result<f64, String> {
        kv.get(k)
            .and_then(|v| v.parse::<f64>().ok())
            .ok_or_else(|| format!("report without `{k}`: {line}"))
    };
    Ok(Figures {
        mode,
        window_s: num("window_s")?,
        fps_mean: num("fps_mean")?,
        fps_min: num("fps_min")?,
        missed: num("missed")? as u64,
        producer_fps: num("producer_fps")?,
        overruns: num("overruns")? as u64,
        cpu_pct: num("cpu_pct")?,
        buffers: num("buffers")? as u64,
        rss_mib: run.peak_rss as f64 / (1024.0 * 1024.0),
    })
}

/// What a configuration runs besides the producer's memcpy.
#[derive(Clone, Copy, PartialEq, Debug)]
enum Mode {
    /// The memcpy into a plain `Vec`, nothing else (the baseline).
    Baseline,
    /// The memcpy into a pooled port buffer, published to this many consumers.
    Ports(usize),
    /// Diagnostic: the baseline's memcpy, then the producer notifies this many
    /// data-triggered containers itself (no ports, no image): what waking the
    /// consumers' threads costs by itself.
    Wakeups(usize),
    /// Diagnostic: like `Wakeups`, but plain std threads woken with `Thread::unpark`
    /// (one futex call each), no runtime at all: the operating system's share.
    Threads(usize),
}

impl Mode {
    fn arg(self) -> String {
        match self {
            Mode::Baseline => "baseline".into(),
            Mode::Ports(n) => format!("ports:{n}"),
            Mode::Wakeups(n) => format!("wakeups:{n}"),
            Mode::Threads(n) => format!("threads:{n}"),
        }
    }

    fn parse(text: &str) -> Option<Mode> {
        if text == "baseline" {
            return Some(Mode::Baseline);
        }
        let (kind, n) = text.split_once(':')?;
        let n = n.parse::<usize>().ok().filter(|n| (1..=1000).contains(n))?;
        match kind {
            "ports" => Some(Mode::Ports(n)),
            "wakeups" => Some(Mode::Wakeups(n)),
            "threads" => Some(Mode::Threads(n)),
            _ => None,
        }
    }

    fn consumers(self) -> usize {
        match self {
            Mode::Baseline => 0,
            Mode::Ports(n) | Mode::Wakeups(n) | Mode::Threads(n) => n,
        }
    }
}

mod child;

pub use child::child;
