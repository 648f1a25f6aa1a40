//! B4 — latency in one process: publish → a data-triggered module in another thread
//! container sees it.
//!
//! A 64-byte message carries its publish time (nanoseconds of [`Instant`] since one
//! epoch shared by the process). The publisher (this benchmark's main thread) stamps
//! the message as the last thing before publishing it; the receiver is the one step of
//! a data-triggered thread container, woken through the runtime's [`Wakeup`] registered
//! on its input, and computes `now - stamp` right after reading the value.
//!
//! Pacing: the publisher sends the next message only after the receiver has recorded
//! the previous one (it spins on an atomic "seen" counter, yielding after a while), and
//! then spins a further `--gap-us` (default 20 µs) so that the receiver is back asleep.
//! Messages therefore never coalesce in the latest-value input, and every latency
//! includes the wakeup of a sleeping thread, as for sporadic sensor data.
//!
//! Measured in the same run, interleaved in `--rounds` rounds so that a noisy moment of
//! the machine hits every variant alike:
//!
//! * `ports`: [`OutputPort<Msg>`] → [`InputPort<Msg>`] (zero-copy buffer ports), the
//!   RESULT line; the same with the container's `wait="spin"` and `wait="adaptive"`
//!   ([`WaitMode`]), with the CPU time the receiver's thread spends per message and as
//!   a share of one core (read with `CLOCK_THREAD_CPUTIME_ID` after each message);
//! * `copy ports`: [`CopyOutputPort<Msg>`] → [`CopyInputPort<Msg>`] (seqlock copies);
//! * `container`: the same data-triggered container without ports: the stamp goes
//!   through two atomics and the publisher notifies the container's [`Wakeup`] itself;
//! * `mpsc`: the baseline, `std::sync::mpsc::channel` and a plain thread blocked in
//!   `recv()`;
//! * diagnostics, plain threads without a container, to tell the parts of a container
//!   wakeup apart: `Wakeup::wait_timeout(50 ms)` (what the container's loop calls),
//!   `Wakeup::wait()` (no time limit; `Wakeup::notify` signals its condition variable
//!   while holding the mutex), a std `Mutex<bool>` + `Condvar` like `Wakeup` but
//!   signalled after the mutex is released, and `thread::park` / `Thread::unpark` (one
//!   futex, no mutex or condition variable).
//!
//! `--pin` pins the publisher to CPU 0 and every receiver to CPU 1, which removes the
//! scheduler's choice of where to wake the receiver.
//!
//! Each run of a variant starts fresh threads and discards its first messages as
//! warm-up (thread start, first page touches, pool growth).

use crate::b3::load_note;
use crate::options::Options;
use ferroc_runtime::container::{Step, ThreadContainer, ThreadOptions, Trigger};
use ferroc_runtime::port::{
    connect, ConnectOptions, CopyInputPort, CopyOutputPort, InputPort, NoUninit, Notifier, Notify,
    OutputPort, WaitMode, Wakeup,
};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{mpsc, Arc, Condvar, Mutex, OnceLock};
use std::time::{Duration, Instant};

const DEFAULT_MESSAGES: u64 = 100_000;
const DEFAULT_GAP_US: u64 = 20;
const DEFAULT_ROUNDS: u64 = 20;
/// Messages at the start of every run that are not recorded.
const WARM_UP: u64 = 200;
/// A message not seen within this time ends the benchmark with an error.
const LOST_AFTER: Duration = Duration::from_secs(5);

/// The 64-byte message: publish time, sequence number, payload.
#[repr(C)]
#[derive(Clone, Copy, Default, Debug)]
pub struct Msg {
    stamp_ns: u64,
    seq: u64,
    payload: [u64; 6],
}

// SAFETY: `repr(C)`, eight `u64` fields in a row: no padding, no uninitialised bytes.
unsafe impl NoUninit for Msg {}

const _: () = assert!(std::mem::size_of::<Msg>() == 64);

/// Nanoseconds since the process-wide epoch (monotonic).
fn now_ns() -> u64 {
    static EPOCH: OnceLock<Instant> = OnceLock::new();
    EPOCH.get_or_init(Instant::now).elapsed().as_nanos() as u64
}

#[derive(Clone, Copy, PartialEq, Debug)]
enum Variant {
    Ports,
    PortsSpin,
    PortsAdaptive,
    CopyPorts,
    Container,
    Mpsc,
    WaitTimeout,
    Wait,
    CondvarUnlocked,
    Park,
}

const VARIANTS: [Variant; 10] = [
    Variant::Ports,
    Variant::PortsSpin,
    Variant::PortsAdaptive,
    Variant::CopyPorts,
    Variant::Container,
    Variant::Mpsc,
    Variant::WaitTimeout,
    Variant::Wait,
    Variant::CondvarUnlocked,
    Variant::Park,
];

impl Variant {
    fn label(self) -> &'static str {
        match self {
            Variant::Ports => "ports         OutputPort -> InputPort, container wait=park    ",
            Variant::PortsSpin => "ports spin    OutputPort -> InputPort, container wait=spin    ",
            Variant::PortsAdaptive => {
                "ports adapt.  OutputPort -> InputPort, wait=adaptive         "
            }
            Variant::CopyPorts => "copy ports    CopyOutputPort -> CopyInputPort, container    ",
            Variant::Container => "container     Wakeup::notify -> container, no ports         ",
            Variant::Mpsc => "mpsc          std::sync::mpsc -> thread blocked in recv()   ",
            Variant::WaitTimeout => "diagnostic    thread in Wakeup::wait_timeout(50 ms)         ",
            Variant::Wait => "diagnostic    thread in Wakeup::wait()                      ",
            Variant::CondvarUnlocked => {
                "diagnostic    thread in Condvar::wait, notified after unlock"
            }
            Variant::Park => "diagnostic    thread in thread::park(), Thread::unpark      ",
        }
    }
}

/// Latency percentiles of one variant, in nanoseconds.
struct Summary {
    n: usize,
    p25: u64,
    p50: u64,
    p75: u64,
    p99: u64,
    p999: u64,
    max: u64,
    mean: f64,
}

impl Summary {
    fn of(mut v: Vec<u64>) -> Summary {
        v.sort_unstable();
        let n = v.len();
        // Nearest rank: the smallest value with at least p of the samples at or below it.
        let rank = |p: f64| v[((p * n as f64).ceil() as usize).clamp(1, n) - 1];
        Summary {
            n,
            p25: rank(0.25),
            p50: rank(0.50),
            p75: rank(0.75),
            p99: rank(0.99),
            p999: rank(0.999),
            max: v[n - 1],
            mean: v.iter().sum::<u64>() as f64 / n as f64,
        }
    }
}

fn us(ns: u64) -> f64 {
    ns as f64 / 1000.0
}

/// Runs B4 and prints its lines. Returns the process exit code.
pub fn run(args: &[String]) -> u8 {
    let parsed =
        Options::parse("b4", args, &["messages", "gap-us", "rounds"], &["pin"]).and_then(|o| {
            Ok((
                o.number("messages", DEFAULT_MESSAGES, 1, 100_000_000)?,
                o.number("gap-us", DEFAULT_GAP_US, 0, 1_000_000)?,
                o.number("rounds", DEFAULT_ROUNDS, 1, 1000)?,
                o.flag("pin"),
            ))
        });
    let (messages, gap_us, rounds, pin) = match parsed {
        Ok(v) => v,
        Err(e) => {
            eprintln!("{e}");
            return 2;
        }
    };
    if cfg!(debug_assertions) {
        println!(
            "b4: warning: not a release build; figures are meaningless (use cargo run --release)"
        );
    }
    let rounds = rounds.min(messages);
    let per_round = messages.div_ceil(rounds);
    let total = per_round * rounds;
    println!(
        "b4: {total} messages of {} bytes per variant ({rounds} rounds of {per_round}, +{WARM_UP} \
         warm-up each), next message {gap_us} µs after the previous was seen, {}; {}",
        std::mem::size_of::<Msg>(),
        if pin {
            "publisher pinned to CPU 0, receivers to CPU 1"
        } else {
            "threads not pinned"
        },
        load_note()
    );
    if total < DEFAULT_MESSAGES {
        println!("b4: note: fewer than the 100,000 messages benchmarks.md asks for");
    }
    let placement = match Placement::new(pin) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("b4: --pin: {e}");
            return 1;
        }
    };
    let gap = Duration::from_micros(gap_us);
    let measured = measure_rounds(rounds as usize, per_round, gap, placement.receiver);
    drop(placement);
    let (samples, cpu) = match measured {
        Ok(m) => m,
        Err(e) => {
            eprintln!("{e}");
            return 1;
        }
    };
    let figures = Figures {
        sums: samples.into_iter().map(Summary::of).collect(),
        cpu,
        messages: total + WARM_UP * rounds,
    };
    figures.print_variants();
    figures.print_findings(gap_us, pin);
    0
}

/// Every variant `per_round` times in each of `rounds` rounds: the latencies of each,
/// and its receiver's CPU time and wall time summed over rounds.
#[allow(clippy::type_complexity)]
fn measure_rounds(
    rounds: usize,
    per_round: u64,
    gap: Duration,
    receiver: Option<usize>,
) -> Result<(Vec<Vec<u64>>, Vec<(u64, u64)>), String> {
    let mut samples: Vec<Vec<u64>> = VARIANTS.iter().map(|_| Vec::new()).collect();
    let mut cpu: Vec<(u64, u64)> = VARIANTS.iter().map(|_| (0, 0)).collect();
    for round in 0..rounds {
        // Rotate the order so no variant always runs first or last in a round.
        for k in 0..VARIANTS.len() {
            let idx = (round + k) % VARIANTS.len();
            let mut run = run_variant(VARIANTS[idx], per_round, gap, receiver)
                .map_err(|e| format!("b4: {:?}: {e}", VARIANTS[idx]))?;
            samples[idx].append(&mut run.latencies);
            cpu[idx].0 += run.cpu_ns;
            cpu[idx].1 += run.wall_ns;
        }
    }
    Ok((samples, cpu))
}

/// What B4 measured: the latencies and receiver CPU of every variant, in `VARIANTS`'s
/// order.
struct Figures {
    sums: Vec<Summary>,
    /// Receiver CPU time and wall time per variant, summed over rounds.
    cpu: Vec<(u64, u64)>,
    /// Messages sent per variant, warm-up included.
    messages: u64,
}

impl Figures {
    /// The receiver's CPU as a share of one core over the run.
    fn cpu_pct(&self, i: usize) -> f64 {
        100.0 * self.cpu[i].0 as f64 / self.cpu[i].1.max(1) as f64
    }

    /// The receiver's CPU time per message.
    fn cpu_us_per_msg(&self, i: usize) -> f64 {
        self.cpu[i].0 as f64 / 1000.0 / self.messages as f64
    }

    /// A latency line per variant, then a CPU line per variant that measured it.
    fn print_variants(&self) {
        for (v, s) in VARIANTS.iter().zip(&self.sums) {
            println!(
                "b4 {}  p25 {:6.2}  p50 {:6.2}  p75 {:6.2}  p99 {:7.2}  p99.9 {:8.2}  max {:9.2}  \
                 mean {:6.2} µs  n={}",
                v.label(),
                us(s.p25),
                us(s.p50),
                us(s.p75),
                us(s.p99),
                us(s.p999),
                us(s.max),
                s.mean / 1000.0,
                s.n
            );
        }
        for (i, v) in VARIANTS.iter().enumerate() {
            if self.cpu[i].0 > 0 {
                println!(
                    "b4 CPU of the receiver  {}  {:6.1} % of a core  {:7.2} µs per message",
                    v.label(),
                    self.cpu_pct(i),
                    self.cpu_us_per_msg(i)
                );
            }
        }
    }

    /// The wait modes compared, the ports against mpsc and the parts of their latency,
    /// and the `RESULT` line.
    fn print_findings(&self, gap_us: u64, pin: bool) {
        let [ports, spin, adaptive, copy, container, chan, wait_timeout, wait, unlocked, park] =
            &self.sums[..]
        else {
            unreachable!("ten variants")
        };
        let cpu_pct = |i: usize| self.cpu_pct(i);
        println!(
            "b4: wait modes: p50 park {:.2} / spin {:.2} / adaptive {:.2} µs (target <= 2 for spin \
             and adaptive), p99 {:.2} / {:.2} / {:.2} µs; receiver CPU {:.1} / {:.1} / {:.1} % of a \
             core (park/unpark thread: p50 {:.2} µs, {:.1} %); {}",
            us(ports.p50),
            us(spin.p50),
            us(adaptive.p50),
            us(ports.p99),
            us(spin.p99),
            us(adaptive.p99),
            cpu_pct(0),
            cpu_pct(1),
            cpu_pct(2),
            us(park.p50),
            cpu_pct(9),
            load_note()
        );
        let ratio = ports.p50 as f64 / chan.p50 as f64;
        println!(
            "b4: ports p50 {:.2} µs (target <= 5), p99 {:.2} µs (target <= 50); p50 {ratio:.2}x of \
             mpsc; p50 parts: ports {:+.2} µs over the bare container, container loop {:+.2} µs over \
             a thread in wait_timeout, time limit {:+.2} µs over wait(), signalling under the mutex \
             {:+.2} µs over after it, mutex + condition variable {:+.2} µs over park; {}",
            us(ports.p50),
            us(ports.p99),
            us(ports.p50) - us(container.p50),
            us(container.p50) - us(wait_timeout.p50),
            us(wait_timeout.p50) - us(wait.p50),
            us(wait.p50) - us(unlocked.p50),
            us(unlocked.p50) - us(park.p50),
            load_note()
        );
        println!(
            "RESULT b4 p50_us={:.2} p99_us={:.2} max_us={:.2} messages={} scope=process \
             mpsc_p50_us={:.2} mpsc_p99_us={:.2} mpsc_max_us={:.2} ratio_p50_vs_mpsc={ratio:.2} \
             copy_p50_us={:.2} copy_p99_us={:.2} container_p50_us={:.2} container_p99_us={:.2} \
             wait_timeout_p50_us={:.2} wait_p50_us={:.2} condvar_unlocked_p50_us={:.2} \
             park_p50_us={:.2} park_p99_us={:.2} park_cpu_pct={:.1} \
             spin_p50_us={:.2} spin_p99_us={:.2} adaptive_p50_us={:.2} adaptive_p99_us={:.2} \
             wait_park_cpu_pct={:.1} wait_spin_cpu_pct={:.1} wait_adaptive_cpu_pct={:.1} \
             gap_us={gap_us} pinned={pin}",
            us(ports.p50),
            us(ports.p99),
            us(ports.max),
            ports.n,
            us(chan.p50),
            us(chan.p99),
            us(chan.max),
            us(copy.p50),
            us(copy.p99),
            us(container.p50),
            us(container.p99),
            us(wait_timeout.p50),
            us(wait.p50),
            us(unlocked.p50),
            us(park.p50),
            us(park.p99),
            cpu_pct(9),
            us(spin.p50),
            us(spin.p99),
            us(adaptive.p50),
            us(adaptive.p99),
            cpu_pct(0),
            cpu_pct(1),
            cpu_pct(2),
        );
    }
}

/// `--pin`: the publisher (this thread) on CPU 0 while B4 runs, receivers on CPU 1.
/// Dropping it gives this thread its former CPU set back.
struct Placement {
    /// The CPU for receivers.
    receiver: Option<usize>,
    saved: Option<libc::cpu_set_t>,
}

impl Placement {
    fn new(pin: bool) -> Result<Placement, String> {
        if !pin {
            return Ok(Placement {
                receiver: None,
                saved: None,
            });
        }
        // SAFETY: an all-zero cpu_set_t is the empty set; the call writes at most its
        // size into it, for the calling thread.
        let saved = unsafe {
            let mut set: libc::cpu_set_t = std::mem::zeroed();
            let size = std::mem::size_of::<libc::cpu_set_t>();
            (libc::sched_getaffinity(0, size, &mut set) == 0).then_some(set)
        };
        let usable = |cpu: usize| {
            // SAFETY: CPU_ISSET reads the set; both CPUs are below CPU_SETSIZE.
            saved
                .as_ref()
                .is_none_or(|set| unsafe { libc::CPU_ISSET(cpu, set) })
        };
        if !usable(0) || !usable(1) {
            return Err("needs CPUs 0 and 1, and this process may not use both".into());
        }
        pin_current(0)?;
        Ok(Placement {
            receiver: Some(1),
            saved,
        })
    }
}

impl Drop for Placement {
    fn drop(&mut self) {
        if let Some(set) = &self.saved {
            // SAFETY: a CPU set read by sched_getaffinity, for the calling thread.
            unsafe { libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), set) };
        }
    }
}

/// Pins the calling thread to `cpu` (the runtime's own placement code).
fn pin_current(cpu: usize) -> Result<(), String> {
    ferroc_runtime::container::pin_current_thread(cpu)
        .map_err(|e| format!("pinning to CPU {cpu}: {e}"))
}

mod drivers;

use drivers::run_variant;
