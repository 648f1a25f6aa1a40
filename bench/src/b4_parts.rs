//! B4 across parts — latency between two part programs over Zenoh: 64-byte values
//! through a ferroc link, next to a bare Zenoh publisher/subscriber pair in the same run.
//!
//! The writer is this process, the reader a child process (`ferroc-bench b4-parts-child`):
//! two programs, two Zenoh sessions on 127.0.0.1, as a bundle runs them.
//!
//! * `ferroc`: a module in a continuous container of part `writer` publishes a value
//!   every `--gap-us`, stamped with `CLOCK_MONOTONIC` (the same clock in both
//!   processes) as the last thing before publishing; its link (reliable, not express:
//!   the QoS ferroc gives a 64-byte library type) carries it to part `reader`, where a
//!   data-triggered container's module computes `now - stamp` after reading it.
//!   The module also reads `In::age()`, the time since the value arrived in the
//!   reader's Zenoh callback: the latency splits into the way to that callback and the
//!   wakeup of the reader's container from it (the `wait=` of `--reader-wait`).
//! * `zenoh`: a publisher with the same QoS (`ferroc_zenoh::free::Qos::of` of the
//!   link) puts the same 64 bytes every `--gap-us`; the reader's subscriber callback
//!   computes `now - stamp`.
//!
//! The reader discards its first messages (session start, warm-up), records the next
//! ones and prints them; the variants alternate in `--rounds` rounds so that a noisy
//! moment of the machine hits both alike.

use crate::b3::load_note;
use crate::options::Options;
use ferroc_runtime::builder::{
    Builder, Conversion, ModuleSpec, Registry, RunningApp, Schedule, StartOptions, StepKind,
    ThreadSpec,
};
use ferroc_runtime::container::ThreadOptions;
use ferroc_runtime::link::transport::{Addresses, Sending};
use ferroc_runtime::link::{LinkSpec, Sharing};
use ferroc_runtime::module::{In, Module, ModuleType, Out, Setup};
use ferroc_runtime::port::WaitMode;
use ferroc_runtime::port::{ConnectOptions, NoUninit};
use ferroc_zenoh::free::Qos;
use ferroc_zenoh::Zenoh;
use serde::{Deserialize, Serialize};
use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use zenoh::Wait;

/// The argument that makes `ferroc-bench` the reader.
pub const CHILD_ARG: &str = "b4-parts-child";
const APP: &str = "b4";
const KEY: &str = "bench/b4/bare";
const WARM_UP: u64 = 500;
const DEFAULT_MESSAGES: u64 = 100_000;
const DEFAULT_GAP_US: u64 = 100;
const DEFAULT_ROUNDS: u64 = 4;

/// The 64-byte value: publish time (CLOCK_MONOTONIC ns), sequence number, payload.
#[repr(C)]
#[derive(Clone, Copy, Default, Debug, Serialize, Deserialize)]
pub struct Msg {
    stamp_ns: u64,
    seq: u64,
    payload: [u64; 6],
}
// SAFETY: `repr(C)`, eight `u64` in a row: no padding.
unsafe impl NoUninit for Msg {}
ferroc_runtime::port_value!(Msg, "bench.Msg", copy);

/// `CLOCK_MONOTONIC` in nanoseconds: one clock for every process of the machine.
pub(crate) fn mono_ns() -> u64 {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: writes one timespec.
    unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut t) };
    t.tv_sec as u64 * 1_000_000_000 + t.tv_nsec as u64
}

/// Writes one value every `gap`, stamped just before publishing.
struct Source {
    out: Out<Msg>,
    next: Option<Instant>,
    seq: u64,
}
static GAP_NS: AtomicU64 = AtomicU64::new(100_000);
impl Module for Source {
    fn update(&mut self) {
        let gap = Duration::from_nanos(GAP_NS.load(Ordering::Relaxed));
        let next = *self.next.get_or_insert_with(Instant::now);
        while Instant::now() < next {
            std::hint::spin_loop();
        }
        self.next = Some(next + gap);
        self.seq += 1;
        let seq = self.seq;
        self.out.publish_with(|m| {
            m.seq = seq;
            m.stamp_ns = mono_ns();
        });
    }
}
impl ModuleType for Source {
    const NAME: &'static str = "bench.Source";
    fn create(m: &mut Setup<'_>) -> Self {
        Source {
            out: m.output("out").build(),
            next: None,
            seq: 0,
        }
    }
}

/// Records `now - stamp` of every value it reads, and how long ago the value arrived
/// in the Zenoh callback (`In::age`).
struct Sink {
    input: In<Msg>,
}
/// Per value: the latency and the part of it spent after the Zenoh callback (ns).
static SEEN: Mutex<Vec<(u64, u64)>> = Mutex::new(Vec::new());
impl Module for Sink {
    fn update(&mut self) {
        if self.input.changed() {
            let stamp = self.input.get().stamp_ns;
            let latency = mono_ns().saturating_sub(stamp);
            let hop = self.input.age().map_or(0, |a| a.as_nanos() as u64);
            SEEN.lock()
                .unwrap_or_else(|e| e.into_inner())
                .push((latency, hop));
        }
    }
}
impl ModuleType for Sink {
    const NAME: &'static str = "bench.Sink";
    fn create(m: &mut Setup<'_>) -> Self {
        Sink {
            input: m.input("in").build(),
        }
    }
}

const LINK: LinkSpec<'static> = LinkSpec {
    id: 0,
    from_part: "writer",
    to_part: "reader",
    model_type: "bench.Msg",
    sharing: Sharing::OnChange {
        min_interval: Duration::ZERO,
    },
    reliable: true,
    deadline: None,
};

fn registry() -> Registry {
    let mut r = Registry::new();
    r.register::<Source>().register::<Sink>();
    r.register_serde::<Msg>();
    r
}

pub(crate) fn addresses(part: &str, writer: &str, reader: &str) -> Addresses {
    Addresses {
        part: part.into(),
        listen: if part == "writer" { writer } else { reader }.into(),
        peers: [
            ("writer".into(), writer.into()),
            ("reader".into(), reader.into()),
        ]
        .into(),
    }
}

/// One part of the ferroc variant, running freely; the reader's container waits as
/// `wait` says.
fn part(
    registry: &Registry,
    part: &str,
    writer: &str,
    reader: &str,
    wait: WaitMode,
) -> Result<RunningApp, String> {
    let mut b = Builder::new(registry);
    let (path, type_name, schedule) = match part {
        "writer" => ("writer/source", "bench.Source", Schedule::Continuous),
        _ => ("reader/sink", "bench.Sink", Schedule::Data),
    };
    let spec = ModuleSpec {
        path,
        type_name,
        params: &[],
        queues: &[],
        ports: &[],
        violations: Default::default(),
    };
    b.add_module(spec).map_err(|e| e.to_string())?;
    b.add_thread(ThreadSpec {
        path: part.into(),
        schedule,
        options: ThreadOptions {
            wait,
            ..ThreadOptions::default()
        },
        steps: vec![(path.into(), StepKind::Update)],
    })
    .map_err(|e| e.to_string())?;
    if part == "writer" {
        b.link_out(&LINK, (path, "out"), Conversion::default())
    } else {
        b.link_in(&LINK, (path, "in"), ConnectOptions::default())
    }
    .map_err(|e| e.to_string())?;
    let network = Zenoh::new(APP, addresses(part, writer, reader), None)?;
    let options = StartOptions {
        network: Some(Arc::new(network)),
        ..StartOptions::default()
    };
    b.start_with(options).map_err(|e| e.to_string())
}

/// A bare Zenoh session of `part` (peer mode, explicit endpoints, no scouting), with
/// ferroc's settings merged under the `--zenoh-config` file `config` if given.
pub(crate) fn session(
    part: &str,
    writer: &str,
    reader: &str,
    config: Option<&std::path::Path>,
) -> Result<zenoh::Session, String> {
    let config = ferroc_zenoh::config::config(&addresses(part, writer, reader), config)?;
    zenoh::open(config).wait().map_err(|e| e.to_string())
}

/// The reader: `b4-parts-child VARIANT WRITER READER N WAIT` prints N latencies and
/// the part of each after the Zenoh callback (ns), a pair a line, after the warm-up.
pub fn child(args: &[String]) -> u8 {
    let [variant, writer, reader, n, wait] = args else {
        eprintln!("usage: {CHILD_ARG} ferroc|zenoh WRITER READER N park|spin|adaptive");
        return 2;
    };
    let Some(wait) = WaitMode::parse(wait) else {
        eprintln!("{CHILD_ARG}: WAIT must be park, spin or adaptive");
        return 2;
    };
    let Ok(n) = n.parse::<u64>() else {
        eprintln!("{CHILD_ARG}: N must be a number");
        return 2;
    };
    let wanted = (WARM_UP + n) as usize;
    let registry = registry();
    let mut keep: Vec<Box<dyn std::any::Any>> = Vec::new();
    let started = match variant.as_str() {
        "ferroc" => {
            part(&registry, "reader", writer, reader, wait).map(|app| keep.push(Box::new(app)))
        }
        _ => session("reader", writer, reader, None).and_then(|s| {
            let sub = s
                .declare_subscriber(KEY)
                .callback(|sample| {
                    let bytes = sample.payload().to_bytes();
                    if let Some(stamp) = bytes.first_chunk::<8>() {
                        let latency = mono_ns().saturating_sub(u64::from_le_bytes(*stamp));
                        SEEN.lock()
                            .unwrap_or_else(|e| e.into_inner())
                            .push((latency, 0));
                    }
                })
                .wait()
                .map_err(|e| e.to_string())?;
            keep.push(Box::new(sub));
            keep.push(Box::new(s));
            Ok(())
        }),
    };
    if let Err(e) = started {
        eprintln!("{CHILD_ARG}: {e}");
        return 1;
    }
    let deadline = Instant::now() + Duration::from_secs(300);
    while SEEN.lock().unwrap_or_else(|e| e.into_inner()).len() < wanted {
        if Instant::now() > deadline {
            eprintln!("{CHILD_ARG}: too few values arrived");
            return 1;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    let seen = std::mem::take(&mut *SEEN.lock().unwrap_or_else(|e| e.into_inner()));
    let mut out = String::new();
    for (latency, hop) in &seen[WARM_UP as usize..wanted] {
        out.push_str(&format!("{latency} {hop}\n"));
    }
    print!("{out}");
    drop(keep);
    0
}

pub(crate) fn free_address() -> Result<String, String> {
    let l = std::net::TcpListener::bind("127.0.0.1:0").map_err(|e| e.to_string())?;
    Ok(l.local_addr().map_err(|e| e.to_string())?.to_string())
}

/// `run` (one configuration of a benchmark, which takes its addresses from
/// [`free_address`] itself), and once more if it fails: a port found free is closed
/// again until the program it is for listens on it, and another program may take it
/// meanwhile (on a busy machine, a connection's own port). The first failure is shown
/// (`what: …`); a second one is the result.
pub(crate) fn retried<T>(
    what: &str,
    mut run: impl FnMut() -> Result<T, String>,
) -> Result<T, String> {
    run().or_else(|e| {
        eprintln!("{what}: {e}; once more, on other ports");
        run()
    })
}

/// One variant once: the reader as a child, the writer here until the child is done.
/// Per value: the latency and the part after the Zenoh callback (ns).
fn once(variant: &str, n: u64, gap: Duration, wait: WaitMode) -> Result<Vec<(u64, u64)>, String> {
    let (writer, reader) = (free_address()?, free_address()?);
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let mut child = Command::new(exe)
        .args([
            CHILD_ARG,
            variant,
            &writer,
            &reader,
            &n.to_string(),
            wait.as_str(),
        ])
        .stdout(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot start the reader: {e}"))?;
    let registry = registry();
    GAP_NS.store(gap.as_nanos() as u64, Ordering::Relaxed);
    let mut app = None;
    let mut bare = None;
    match variant {
        "ferroc" => app = Some(part(&registry, "writer", &writer, &reader, wait)?),
        _ => bare = Some(bare_writer(&writer, &reader)?),
    }
    let stdout = child.stdout.take().ok_or("no output of the reader")?;
    let reading = std::thread::spawn(move || {
        BufReader::new(stdout)
            .lines()
            .map_while(Result::ok)
            .filter_map(|l| {
                let (latency, hop) = l.split_once(' ')?;
                Some((latency.parse::<u64>().ok()?, hop.parse::<u64>().ok()?))
            })
            .collect::<Vec<(u64, u64)>>()
    });
    let publisher = bare.as_ref().map(|(_, p)| p);
    write_until_read(&mut child, publisher, gap)?;
    drop(app);
    drop(bare);
    let status = child.wait().map_err(|e| e.to_string())?;
    let samples = reading.join().map_err(|_| "reading the reader failed")?;
    if !status.success() || samples.len() as u64 != n {
        return Err(format!(
            "the reader failed ({status}, {} values)",
            samples.len()
        ));
    }
    Ok(samples)
}

/// The bare Zenoh writer: a session and a publisher with the QoS ferroc gives the
/// link, so that only ferroc's own work differs.
fn bare_writer(
    writer: &str,
    reader: &str,
) -> Result<(zenoh::Session, zenoh::pubsub::Publisher<'static>), String> {
    let s = session("writer", writer, reader, None)?;
    let qos = Qos::of(&Sending {
        to_part: LINK.to_part.into(),
        topic: "writer/source/out".into(),
        model_type: LINK.model_type.into(),
        sharing: LINK.sharing,
        reliable: LINK.reliable,
    });
    let p = s
        .declare_publisher(KEY)
        .congestion_control(qos.congestion)
        .express(qos.express)
        .wait()
        .map_err(|e| e.to_string())?;
    Ok((s, p))
}

/// Until the reader `child` is done (at most 300 s): the bare `publisher` puts a
/// stamped value every `gap`; ferroc's writer part (no publisher) runs on its own.
fn write_until_read(
    child: &mut std::process::Child,
    publisher: Option<&zenoh::pubsub::Publisher<'static>>,
    gap: Duration,
) -> Result<(), String> {
    let mut next = Instant::now();
    let mut seq = 0u64;
    let deadline = Instant::now() + Duration::from_secs(300);
    while child.try_wait().map_err(|e| e.to_string())?.is_none() {
        if Instant::now() > deadline {
            let _ = child.kill();
            return Err("the reader did not finish".into());
        }
        match publisher {
            Some(publisher) => {
                while Instant::now() < next {
                    std::hint::spin_loop();
                }
                next += gap;
                seq += 1;
                let mut bytes = [0u8; 64];
                bytes[8..16].copy_from_slice(&seq.to_le_bytes());
                bytes[..8].copy_from_slice(&mono_ns().to_le_bytes());
                publisher
                    .put(bytes.to_vec())
                    .wait()
                    .map_err(|e| e.to_string())?;
            }
            None => std::thread::sleep(Duration::from_millis(5)),
        }
    }
    Ok(())
}

/// p50, p99, max (nearest rank) in microseconds.
pub(crate) fn percentiles(mut v: Vec<u64>) -> (f64, f64, f64) {
    v.sort_unstable();
    let rank = |p: f64| v[((p * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1];
    let us = |ns: u64| ns as f64 / 1000.0;
    (us(rank(0.5)), us(rank(0.99)), us(v[v.len() - 1]))
}

/// Runs B4 across parts and prints its lines. Returns the process exit code.
pub fn run(args: &[String]) -> u8 {
    let parsed = Options::parse(
        "b4-parts",
        args,
        &["messages", "gap-us", "rounds", "reader-wait"],
        &[],
    )
    .and_then(|o| {
        let wait = match o.text("reader-wait") {
            None => WaitMode::Park,
            Some(w) => WaitMode::parse(w)
                .ok_or_else(|| format!("--reader-wait {w}: must be park, spin or adaptive"))?,
        };
        Ok((
            o.number("messages", DEFAULT_MESSAGES, 1, 100_000_000)?,
            o.number("gap-us", DEFAULT_GAP_US, 1, 1_000_000)?,
            o.number("rounds", DEFAULT_ROUNDS, 1, 1000)?,
            wait,
        ))
    });
    let (messages, gap_us, rounds, wait) = match parsed {
        Ok(v) => v,
        Err(e) => {
            eprintln!("{e}");
            return 2;
        }
    };
    if cfg!(debug_assertions) {
        println!("b4-parts: warning: not a release build; figures are meaningless");
    }
    let per_round = messages.div_ceil(rounds.min(messages));
    println!(
        "b4-parts: {} values of 64 bytes per variant between two programs over Zenoh on \
         127.0.0.1 ({rounds} rounds, +{WARM_UP} warm-up each), one every {gap_us} µs, the \
         reader's container wait={}; {}",
        per_round * rounds,
        wait.as_str(),
        load_note()
    );
    let gap = Duration::from_micros(gap_us);
    let variants = ["ferroc", "zenoh"];
    let mut samples: [Vec<(u64, u64)>; 2] = [Vec::new(), Vec::new()];
    for round in 0..rounds as usize {
        for k in 0..2 {
            let i = (round + k) % 2;
            let what = format!("b4-parts: {}", variants[i]);
            match retried(&what, || once(variants[i], per_round, gap, wait)) {
                Ok(mut s) => samples[i].append(&mut s),
                Err(e) => {
                    eprintln!("b4-parts: {}: {e}", variants[i]);
                    return 1;
                }
            }
        }
    }
    let [ferroc, bare] = samples;
    let n = ferroc.len();
    let to_callback: Vec<u64> = ferroc.iter().map(|(l, h)| l.saturating_sub(*h)).collect();
    let hop: Vec<u64> = ferroc.iter().map(|(_, h)| *h).collect();
    let (f50, f99, fmax) = percentiles(ferroc.into_iter().map(|(l, _)| l).collect());
    let (z50, z99, zmax) = percentiles(bare.into_iter().map(|(l, _)| l).collect());
    let (c50, c99, _) = percentiles(to_callback);
    let (h50, h99, _) = percentiles(hop);
    println!("b4-parts ferroc link   p50 {f50:8.2}  p99 {f99:8.2}  max {fmax:9.2} µs  n={n}");
    println!("  of which up to the reader's Zenoh callback  p50 {c50:8.2}  p99 {c99:8.2} µs");
    println!(
        "  of which callback → module (wait={})      p50 {h50:8.2}  p99 {h99:8.2} µs",
        wait.as_str()
    );
    println!("b4-parts bare Zenoh    p50 {z50:8.2}  p99 {z99:8.2}  max {zmax:9.2} µs");
    let ratio = f50 / z50;
    println!(
        "RESULT b4-parts p50_us={f50:.2} p99_us={f99:.2} max_us={fmax:.2} messages={n} \
         scope=parts zenoh_p50_us={z50:.2} zenoh_p99_us={z99:.2} zenoh_max_us={zmax:.2} \
         ratio_p50_vs_zenoh={ratio:.2} to_callback_p50_us={c50:.2} hop_p50_us={h50:.2} \
         reader_wait={} gap_us={gap_us}",
        wait.as_str()
    );
    0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The race `retried` is for: the first try listens on a port another program took
    /// after `free_address` found it free; the second finds a free one and succeeds.
    #[test]
    fn a_configuration_whose_port_was_taken_runs_once_more_on_another() {
        let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
        let taken_address = taken.local_addr().unwrap().to_string();
        let mut tries = Vec::new();
        let listened = retried("test", || {
            let address = match tries.is_empty() {
                true => taken_address.clone(),
                false => free_address()?,
            };
            tries.push(address.clone());
            std::net::TcpListener::bind(&address)
                .map(|_| address)
                .map_err(|e| e.to_string())
        });
        assert_eq!(tries.len(), 2, "{tries:?}");
        assert_eq!(listened, Ok(tries[1].clone()));
        assert_ne!(tries[1], taken_address);
        drop(taken);
    }

    /// A configuration that succeeds runs once; one that fails twice is a failure.
    #[test]
    fn a_configuration_runs_at_most_twice() {
        let mut runs = 0;
        let once = retried("test", || {
            runs += 1;
            Ok::<_, String>(runs)
        });
        assert_eq!((once, runs), (Ok(1), 1));
        let mut runs = 0;
        let failed: Result<(), String> = retried("test", || {
            runs += 1;
            Err(format!("failure {runs}"))
        });
        assert_eq!((failed, runs), (Err("failure 2".to_string()), 2));
    }
}
