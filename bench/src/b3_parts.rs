//! B3 across parts — image fan-out between programs: the B3 producer (1920×1080 RGB,
//! 6,220,800 bytes, at 50 fps) in one part program and 1, 7 or 15 consumers, each in a
//! part program of its own, on one computer. Three variants in the same run:
//!
//! * `ferroc-shm`: the producer's `ferroc_std.Image` output linked to each consumer
//!   part (one link per consumer part, as a bundle plans a connection that crosses
//!   parts; latest-value inputs, so not reliable), shared memory on (ferroc's
//!   defaults);
//! * `ferroc-net`: the same with `transport/shared_memory/enabled: false` in every
//!   program's `--zenoh-config`;
//! * `zenoh-shm`: a bare Zenoh publisher that copies each frame into a buffer of its
//!   own `ShmProvider` and puts it once; one bare subscriber process per consumer.
//!
//! Every program is a child process of this benchmark (`b3-parts-child`, the roles are
//! in `roles.rs`). The producer copies a source frame into the value (the in-process
//! B3's memcpy), writes the frame number and, last, a `CLOCK_MONOTONIC` stamp; a
//! consumer takes `now - stamp` in its step (ferroc: a data-triggered container's
//! module reading its input, the container `wait="inline"` so that its cycle runs in
//! Zenoh's callback as the bare work does, `--consumer-wait park` for a thread of its
//! own woken by each frame; bare: the subscriber's callback). The first
//! [`WARM_UP`] frames are not measured; the window is the next `--frames` frames. The
//! producer tells this process where the window starts and ends; at both moments this
//! process reads every program's CPU time (`utime + stime` of `/proc/PID/stat`) and
//! resident memory (`VmRSS` of `/proc/PID/status`): CPU % of all programs together
//! (100 % = one core), each program's RSS at the window's end and how much it grew
//! over the window, in all and in private pages (`RssAnon`; `--frames 10000` for
//! "memory flat"); and how many frames the consumers saw that did not come in shared
//! memory (a transport that has none copies the frame through its socket, which
//! shows in CPU and latency).
//!
//! Every program sets Zenoh's runtime threads as a bundle's part program does
//! (`ferroc_zenoh::config::runtime`), unless `--zenoh-runtime` gives them
//! (`--zenoh-runtime '()'`: Zenoh's own).

mod roles;

use crate::b3::load_note;
use crate::b4_parts::{free_address, percentiles, retried};
use crate::options::Options;
use ferroc_runtime::port::WaitMode;
use std::io::{BufRead, BufReader, Write};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{channel, Receiver, Sender};
use std::time::{Duration, Instant};

pub use roles::child;

/// `--zenoh` and `--zenoh-runtime` as the children's environment.
static TUNING: std::sync::Mutex<Vec<(&str, String)>> = std::sync::Mutex::new(Vec::new());

/// The argument that makes `ferroc-bench` one program of a configuration.
pub const CHILD_ARG: &str = "b3-parts-child";
/// 1920 × 1080 pixels × 3 bytes (RGB).
pub(crate) const FRAME_BYTES: usize = crate::b3::FRAME_BYTES;
/// 50 fps.
const PERIOD: Duration = Duration::from_millis(20);
/// Frames before the window: sessions connect, pages are touched the first time.
const WARM_UP: u64 = 50;
const VARIANTS: [&str; 3] = ["ferroc-shm", "ferroc-net", "zenoh-shm"];
const DEFAULT_FRAMES: u64 = 500;
/// `--mesh on`: Zenoh's gossip autoconnect in every program (`scouting/gossip/autoconnect`
/// as Zenoh sets it), so every consumer also connects to every other, as ferroc's
/// parts did before they connected only to the parts they link with. Off by default:
/// ferroc's own configuration, which the bare programs take too.
static MESH: AtomicBool = AtomicBool::new(false);
/// How the children learn `--mesh`.
pub(crate) const MESH_ENV: &str = "FERROC_B3_MESH";
/// `--zenoh KEY=VALUE;…`: Zenoh settings for every program, ferroc's and bare (the
/// same configuration on both sides), e.g. `transport/link/rx/buffer_size=65536`.
pub(crate) const ZENOH_ENV: &str = "FERROC_B3_ZENOH";
/// `--zenoh-runtime RON`: Zenoh's runtime threads (`ZENOH_RUNTIME`) of every program.
const RUNTIME_ENV: &str = "ZENOH_RUNTIME";
/// `--consumer-wait MODE`: the `wait=` of ferroc's consumer containers.
const WAIT_ENV: &str = "FERROC_B3_CONSUMER_WAIT";
/// Without `--consumer-wait`: the Viewer's step reads 16 bytes and notes a latency,
/// short and never blocking, which is what `wait="inline"` is for (its cycle runs in
/// Zenoh's callback, as the bare subscriber's work does).
const DEFAULT_WAIT: WaitMode = WaitMode::Inline;

/// How ferroc's consumer containers wait for data (`--consumer-wait`, handed to the
/// children in [`WAIT_ENV`]).
pub(crate) fn consumer_wait() -> WaitMode {
    let wait = std::env::var(WAIT_ENV).ok();
    wait.and_then(|w| WaitMode::parse(&w))
        .unwrap_or(DEFAULT_WAIT)
}

/// What one configuration measured.
struct Figures {
    variant: &'static str,
    consumers: usize,
    fps: Vec<f64>,
    missed: u64,
    /// Frames the consumers saw that did not come in shared memory (a transport
    /// without it: the frame copied through the socket).
    not_shared: u64,
    producer_fps: f64,
    cpu_pct: f64,
    /// MiB at the window's end: producer, then each consumer.
    rss: Vec<f64>,
    /// MiB grown over the window, same order: all resident pages, and the private
    /// ones (`RssAnon`: a leak grows these; shared memory a program touches for the
    /// first time grows only the first).
    growth: Vec<f64>,
    anon_growth: Vec<f64>,
    latencies: Vec<u64>,
}

/// One reading of every program: CPU ticks in total, each one's `VmRSS` and
/// `RssAnon` in KiB.
struct Sample {
    at: Instant,
    ticks: u64,
    rss_kib: Vec<u64>,
    anon_kib: Vec<u64>,
}

fn sample(pids: &[u32]) -> Sample {
    let read = |pid: u32, file: &str| std::fs::read_to_string(format!("/proc/{pid}/{file}"));
    let ticks = |stat: String| -> u64 {
        // After the command's `(…)`: state is field 3, utime 14, stime 15.
        let rest = stat.rsplit_once(')').map_or("", |(_, r)| r).to_owned();
        let fields: Vec<&str> = rest.split_whitespace().collect();
        let field = |i: usize| fields.get(i).and_then(|f| f.parse::<u64>().ok());
        field(11).unwrap_or(0) + field(12).unwrap_or(0)
    };
    let kib = |status: &str, key: &str| -> u64 {
        let line = status.lines().find(|l| l.starts_with(key));
        let kib = line.and_then(|l| l.split_whitespace().nth(1)?.parse::<u64>().ok());
        kib.unwrap_or(0)
    };
    let status: Vec<String> = (pids.iter())
        .map(|&p| read(p, "status").unwrap_or_default())
        .collect();
    Sample {
        at: Instant::now(),
        ticks: pids.iter().map(|&p| read(p, "stat").map_or(0, ticks)).sum(),
        rss_kib: status.iter().map(|s| kib(s, "VmRSS:")).collect(),
        anon_kib: status.iter().map(|s| kib(s, "RssAnon:")).collect(),
    }
}

/// Ticks of `/proc/PID/stat` per second.
fn clock_ticks() -> f64 {
    // SAFETY: sysconf only reads a system setting.
    let t = unsafe { libc::sysconf(libc::_SC_CLK_TCK) };
    if t > 0 {
        t as f64
    } else {
        100.0
    }
}

/// A running configuration: its programs (producer first) and their lines.
struct Programs {
    children: Vec<Child>,
    lines: Receiver<(usize, String)>,
    send: Sender<(usize, String)>,
    producer_stdin: Option<ChildStdin>,
}

impl Programs {
    fn start(
        &mut self,
        variant: &str,
        index: usize,
        frames: u64,
        all: &[String],
    ) -> Result<(), String> {
        let exe = std::env::current_exe().map_err(|e| e.to_string())?;
        let mesh = if MESH.load(Ordering::Relaxed) {
            "on"
        } else {
            "off"
        };
        let mut command = Command::new(exe);
        for (key, value) in TUNING.lock().unwrap_or_else(|e| e.into_inner()).iter() {
            command.env(key, value);
        }
        let mut child = command
            .env(MESH_ENV, mesh)
            .arg(CHILD_ARG)
            .args([variant, &index.to_string(), &frames.to_string()])
            .args(all)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .map_err(|e| format!("cannot start a program: {e}"))?;
        let stdout = child.stdout.take().ok_or("no output of a program")?;
        let send = self.send.clone();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                let _ = send.send((index, line));
            }
            let _ = send.send((index, "EXIT".into()));
        });
        if index == 0 {
            self.producer_stdin = child.stdin.take();
        }
        self.children.push(child);
        Ok(())
    }

    fn pids(&self) -> Vec<u32> {
        self.children.iter().map(Child::id).collect()
    }

    /// The next line of any program, or an error after `limit`.
    fn next(&self, deadline: Instant, waiting_for: &str) -> Result<(usize, String), String> {
        let left = deadline.saturating_duration_since(Instant::now());
        self.lines
            .recv_timeout(left)
            .map_err(|_| format!("timed out waiting for {waiting_for}"))
    }
}

impl Drop for Programs {
    fn drop(&mut self) {
        drop(self.producer_stdin.take());
        let until = Instant::now() + Duration::from_secs(10);
        for child in &mut self.children {
            while matches!(child.try_wait(), Ok(None)) && Instant::now() < until {
                std::thread::sleep(Duration::from_millis(20));
            }
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}

/// What the consumers reported: fps each, missed frames, every latency.
#[derive(Default)]
struct Reports {
    fps: Vec<f64>,
    missed: u64,
    not_shared: u64,
    latencies: Vec<u64>,
    done: usize,
    /// The consumers that reported.
    from: Vec<usize>,
    /// The newest frame any consumer saw.
    last_seq: u64,
}

impl Reports {
    fn read(&mut self, consumer: usize, line: &str) -> Result<(), String> {
        if let Some(seen) = line.strip_prefix("SEEN ") {
            let value = |key: &str| {
                seen.split_whitespace()
                    .find_map(|w| w.strip_prefix(key)?.strip_prefix('='))
                    .and_then(|v| v.parse::<f64>().ok())
                    .ok_or_else(|| format!("a consumer reported without `{key}`: {line}"))
            };
            self.fps.push(value("fps")?);
            self.missed += value("missed")? as u64;
            let all = value("all")? as u64;
            self.not_shared += all.saturating_sub(value("shared")? as u64);
            self.last_seq = self.last_seq.max(value("last")? as u64);
        } else if let Some(lat) = line.strip_prefix("LAT") {
            self.latencies
                .extend(lat.split_whitespace().filter_map(|n| n.parse::<u64>().ok()));
            self.done += 1;
            self.from.push(consumer);
        }
        Ok(())
    }
}

/// One configuration: `consumers` consumer programs, then the producer; the figures.
fn once(variant: &'static str, consumers: usize, frames: u64) -> Result<Figures, String> {
    let all: Vec<String> = (0..=consumers)
        .map(|_| free_address())
        .collect::<Result<_, _>>()?;
    let (send, lines) = channel();
    let mut p = Programs {
        children: Vec::new(),
        lines,
        send,
        producer_stdin: None,
    };
    // The producer is started last (its index 0 is its place in `all`), so children[0]
    // is a consumer until it is moved to the front.
    for index in 1..=consumers {
        p.start(variant, index, frames, &all)?;
    }
    let start_limit = Instant::now() + Duration::from_secs(120);
    let mut ready = 0;
    while ready < consumers {
        let (_, line) = p.next(start_limit, "the consumers to start")?;
        match line.as_str() {
            "READY" => ready += 1,
            "EXIT" => return Err("a consumer ended before it was ready".into()),
            _ => {}
        }
    }
    p.start(variant, 0, frames, &all)?;
    p.children.rotate_right(1);
    measure(variant, consumers, frames, &p)
}

/// Reads the programs' lines until every consumer reported; samples at `START`/`END`.
fn measure(
    variant: &'static str,
    consumers: usize,
    frames: u64,
    p: &Programs,
) -> Result<Figures, String> {
    let pids = p.pids();
    let limit = PERIOD * (3 * (WARM_UP + frames)) as u32 + Duration::from_secs(120);
    let deadline = Instant::now() + limit;
    let (mut start, mut end) = (None, None);
    let mut reports = Reports::default();
    while reports.done < consumers {
        match p.next(deadline, "the consumers' reports")? {
            (0, l) if l == "START" => start = Some(sample(&pids)),
            (0, l) if l == "END" => end = Some(sample(&pids)),
            (0, l) if l == "EXIT" => return Err("the producer ended early".into()),
            (i, l) if l == "EXIT" && !reports.from.contains(&i) => {
                return Err(format!("consumer c{i} ended without its report"))
            }
            (i, l) => reports.read(i, &l)?,
        }
    }
    let Some(start) = start else {
        return Err("the producer did not reach the window".into());
    };
    // A producer slower than 50 fps may not have reached the window's last frame when
    // the consumers stopped: its rate is then what they saw of it.
    let published = match end {
        Some(_) => frames - 1,
        None => reports.last_seq.saturating_sub(WARM_UP + 1),
    };
    let end = end.unwrap_or_else(|| sample(&pids));
    let wall = end.at.duration_since(start.at).as_secs_f64().max(1e-9);
    let mib = |kib: u64| kib as f64 / 1024.0;
    let grown = |a: &[u64], b: &[u64]| -> Vec<f64> {
        a.iter().zip(b).map(|(a, b)| mib(*b) - mib(*a)).collect()
    };
    Ok(Figures {
        variant,
        consumers,
        fps: reports.fps,
        missed: reports.missed,
        not_shared: reports.not_shared,
        producer_fps: published as f64 / wall,
        cpu_pct: (end.ticks - start.ticks) as f64 / clock_ticks() / wall * 100.0,
        rss: end.rss_kib.iter().map(|k| mib(*k)).collect(),
        growth: grown(&start.rss_kib, &end.rss_kib),
        anon_growth: grown(&start.anon_kib, &end.anon_kib),
        latencies: reports.latencies,
    })
}

/// Prints a configuration's line and its RESULT line; its CPU % and p50 (µs).
fn report(f: Figures) -> (f64, f64) {
    let n = f.fps.len().max(1) as f64;
    let fps_mean = f.fps.iter().sum::<f64>() / n;
    let fps_min = f.fps.iter().copied().fold(f64::INFINITY, f64::min);
    let rss_consumer = f.rss[1..].iter().copied().fold(0.0, f64::max);
    // Consumers only (the producer's figures are its own).
    let max = |v: &[f64]| v[1..].iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let (growth_max, anon_max) = (max(&f.growth), max(&f.anon_growth));
    let samples = f.latencies.len();
    let (p50, p99, _) = if samples == 0 {
        (f64::NAN, f64::NAN, f64::NAN)
    } else {
        percentiles(f.latencies)
    };
    let (variant, consumers) = (f.variant, f.consumers);
    println!(
        "b3-parts {variant:<10} consumers={consumers:>2}  fps mean {fps_mean:5.2} min \
         {fps_min:5.2}  missed {}  not in SHM {}  producer {:5.2} fps  cpu {:6.1} %  RSS producer {:5.1} \
         MiB, consumer max {rss_consumer:5.1} MiB, consumer growth max {growth_max:+.1} MiB \
         (private {anon_max:+.1})  latency p50 {p50:8.1} p99 {p99:8.1} µs (n={samples})",
        f.missed, f.not_shared, f.producer_fps, f.cpu_pct, f.rss[0]
    );
    println!(
        "RESULT b3-parts variant={} consumers={consumers} fps_mean={fps_mean:.2} \
         fps_min={fps_min:.2} missed={} not_shm={} producer_fps={:.2} cpu_pct={:.1} \
         rss_producer_mib={:.1} rss_consumer_max_mib={rss_consumer:.1} \
         rss_growth_max_mib={growth_max:.2} anon_growth_max_mib={anon_max:.2} \
         rss_growth_producer_mib={:.2} p50_us={p50:.1} p99_us={p99:.1}",
        variant.replace('-', "_"),
        f.missed,
        f.not_shared,
        f.producer_fps,
        f.cpu_pct,
        f.rss[0],
        f.growth[0],
    );
    let _ = std::io::stdout().flush();
    (f.cpu_pct, p50)
}

/// `--consumers 1,7,15` and `--variants a,b`: the lists, checked.
fn lists(o: &Options) -> Result<(Vec<usize>, Vec<&'static str>), String> {
    let counts = o.text("consumers").unwrap_or("1,7,15");
    let counts: Vec<usize> = (counts.split(','))
        .map(|c| {
            c.trim()
                .parse::<usize>()
                .ok()
                .filter(|n| (1..=32).contains(n))
        })
        .collect::<Option<_>>()
        .ok_or_else(|| {
            format!("b3-parts: `--consumers {counts}`: numbers from 1 to 32, comma-separated")
        })?;
    let names = o
        .text("variants")
        .unwrap_or("ferroc-shm,ferroc-net,zenoh-shm");
    let variants = (names.split(','))
        .map(|v| VARIANTS.iter().copied().find(|k| *k == v.trim()))
        .collect::<Option<Vec<_>>>()
        .ok_or_else(|| {
            format!(
                "b3-parts: `--variants {names}`: a comma-separated list of {}",
                VARIANTS.join(", ")
            )
        })?;
    Ok((counts, variants))
}

/// Runs B3 across parts and prints its lines; the exit code.
pub fn run(args: &[String]) -> u8 {
    let parsed = Options::parse(
        "b3-parts",
        args,
        &[
            "frames",
            "consumers",
            "variants",
            "mesh",
            "zenoh",
            "zenoh-runtime",
            "consumer-wait",
        ],
        &[],
    )
    .and_then(|o| {
        let mut tuning = TUNING.lock().unwrap_or_else(|e| e.into_inner());
        tuning.extend(o.text("zenoh").map(|z| (ZENOH_ENV, z.to_owned())));
        tuning.extend(o.text("zenoh-runtime").map(|r| (RUNTIME_ENV, r.to_owned())));
        if let Some(w) = o.text("consumer-wait") {
            if WaitMode::parse(w).is_none() {
                return Err(format!(
                    "b3-parts: `--consumer-wait {w}`: park, spin, adaptive or inline"
                ));
            }
            tuning.push((WAIT_ENV, w.to_owned()));
        }
        let mesh = match o.text("mesh").unwrap_or("off") {
            "on" => true,
            "off" => false,
            other => return Err(format!("b3-parts: `--mesh {other}`: on or off")),
        };
        MESH.store(mesh, Ordering::Relaxed);
        Ok((
            o.number("frames", DEFAULT_FRAMES, 2, 1_000_000)?,
            lists(&o)?,
        ))
    });
    let (frames, (counts, variants)) = match parsed {
        Ok(v) => v,
        Err(e) => {
            eprintln!("{e}");
            return 2;
        }
    };
    if cfg!(debug_assertions) {
        println!("b3-parts: warning: not a release build; figures are meaningless");
    }
    println!(
        "b3-parts: 1920x1080 RGB frames ({FRAME_BYTES} bytes) at 50 fps from one part program \
         to each consumer's own; {frames} frames measured per configuration after {WARM_UP}; {}",
        load_note()
    );
    let tuning = TUNING.lock().unwrap_or_else(|e| e.into_inner()).clone();
    let wait =
        (tuning.iter().find(|(k, _)| *k == WAIT_ENV)).map_or(DEFAULT_WAIT.as_str(), |t| &t.1);
    let mut tuning: Vec<String> = (tuning.iter())
        .filter(|(k, _)| *k != WAIT_ENV)
        .map(|(k, v)| format!("{k}='{v}'"))
        .collect();
    if !tuning.iter().any(|t| t.starts_with(RUNTIME_ENV)) {
        // The children inherit this environment; without it they set ferroc's.
        tuning.push(match std::env::var(RUNTIME_ENV) {
            Ok(v) => format!("{RUNTIME_ENV}='{v}' (the environment's)"),
            Err(_) => {
                let ours = ferroc_zenoh::config::runtime::DEFAULT;
                format!("{RUNTIME_ENV}='{ours}' (ferroc's, as in a bundle)")
            }
        });
    }
    println!(
        "b3-parts: ferroc's consumers wait=\"{wait}\"; gossip mesh {}; every program's tuning: {}",
        if MESH.load(Ordering::Relaxed) {
            "on"
        } else {
            "off"
        },
        if tuning.is_empty() {
            "none".to_string()
        } else {
            tuning.join(" ")
        }
    );
    let mut table: Vec<(&str, usize, f64, f64)> = Vec::new();
    let mut failed = 0;
    for &consumers in &counts {
        for &variant in &variants {
            let what = format!("b3-parts: {variant} with {consumers} consumers");
            match retried(&what, || once(variant, consumers, frames)) {
                Ok(f) => {
                    let (cpu, p50) = report(f);
                    table.push((variant, consumers, cpu, p50));
                }
                // The other configurations still tell something: go on, exit 1 at the end.
                Err(e) => {
                    eprintln!("b3-parts: {variant} with {consumers} consumers: {e}");
                    failed = 1;
                }
            }
        }
    }
    print_ratios(&table, &counts);
    failed
}

/// The targets' ratios: CPU at the most consumers against one, ferroc's p50 against
/// bare Zenoh shared memory and against ferroc without it.
fn print_ratios(table: &[(&str, usize, f64, f64)], counts: &[usize]) {
    let get = |v: &str, n: usize| table.iter().find(|r| r.0 == v && r.1 == n);
    let (first, last) = (counts[0], counts[counts.len() - 1]);
    for v in VARIANTS.iter().filter(|_| first != last) {
        if let (Some(a), Some(b)) = (get(v, first), get(v, last)) {
            println!(
                "b3-parts {v}: CPU({last}) / CPU({first}) = {:.2} (target <= 1.5)",
                b.2 / a.2
            );
        }
    }
    for &n in counts {
        if let (Some(f), Some(z)) = (get("ferroc-shm", n), get("zenoh-shm", n)) {
            print!(
                "b3-parts consumers={n}: p50 ferroc-shm / zenoh-shm {:.2}",
                f.3 / z.3
            );
            if let Some(net) = get("ferroc-net", n) {
                print!(", ferroc-net / ferroc-shm {:.2}", net.3 / f.3);
            }
            println!();
        }
    }
    println!("b3-parts: {}", load_note());
}
