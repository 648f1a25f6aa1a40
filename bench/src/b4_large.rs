//! B4 across parts, large values: p50/p99 latency of 64 B, 64 KB, 1 MB and 6.2 MB
//! (1080p RGB) values between two programs on 127.0.0.1, five variants in the same run:
//!
//! * `ferroc-shm`: a `ferroc_std.Image` link between two part programs, shared memory
//!   on (ferroc's defaults: values of 4 KB and more go through the writer's pool); the
//!   writer module fills a buffer its output lends it (`Out::lend`: a pool buffer, sent
//!   without a copy);
//! * `ferroc-copy`: the same, but the module fills a buffer of its own (the image's
//!   `data` resized in place), which the link copies into a pool buffer;
//! * `ferroc-net`: the same with `transport/shared_memory/enabled: false` in both
//!   programs' `--zenoh-config`: every byte through the socket;
//! * `zenoh-shm`: a bare Zenoh publisher that allocates each value in its own
//!   `ShmProvider` (64 MiB, POSIX), fills it and puts it; a bare subscriber reads the
//!   stamp in its callback;
//! * `zenoh-net`: the bare pair with shared memory off, the value a fresh `Vec`.
//!
//! Every writer fills the value (the frame number in every byte), stamps its first 8
//! bytes with `CLOCK_MONOTONIC` as the last thing before publishing, and the reader
//! takes `now - stamp`: in ferroc's reader module after it read the value from its input
//! (a data-triggered container), in the bare subscriber's callback. The reader is a
//! child process (`ferroc-bench b4-large-child`); variants alternate per round.
//!
//! Every program runs as a part program does (as in `b3-parts`): Zenoh's runtime
//! threads from ferroc's `ZENOH_RUNTIME` (`config::runtime::use_default`, unless the
//! environment sets one), and ferroc's Zenoh configuration of its part, the bare pair
//! too (the writer connects, the reader only listens).

mod bare;

use crate::b3::load_note;
use crate::b4_parts::{addresses, free_address, mono_ns, percentiles};
use crate::options::Options;
use ferroc_runtime::builder::{
    Builder, Conversion, ModuleSpec, Registry, RunningApp, Schedule, StartOptions, StepKind,
    ThreadSpec,
};
use ferroc_runtime::container::ThreadOptions;
use ferroc_runtime::link::{LinkSpec, Sharing};
use ferroc_runtime::module::{In, Module, ModuleType, Out, Setup};
use ferroc_runtime::port::{ConnectOptions, WaitMode};
use ferroc_std::Image;
use ferroc_zenoh::Zenoh;
use std::io::{BufRead, BufReader};
use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use zenoh::Wait;

/// The argument that makes `ferroc-bench` the reader.
pub const CHILD_ARG: &str = "b4-large-child";
const APP: &str = "b4large";
const KEY: &str = "bench/b4large/bare";
const SIZES: [usize; 4] = [64, 64 * 1024, 1 << 20, 1920 * 1080 * 3];
const VARIANTS: [&str; 5] = [
    "ferroc-shm",
    "ferroc-copy",
    "ferroc-net",
    "zenoh-shm",
    "zenoh-net",
];
const WARM_UP: usize = 20;
/// How long the reader waits for a value (the first one included) before it gives up.
const STALLED: Duration = Duration::from_secs(20);
const DEFAULT_MESSAGES: u64 = 300;
const DEFAULT_ROUNDS: u64 = 2;

/// One value every: 50 per second for a 1080p frame (B3's rate), faster for smaller.
fn gap(size: usize) -> Duration {
    Duration::from_millis(match size {
        0..=65536 => 2,
        65537..=1048576 => 10,
        _ => 20,
    })
}

/// The size the writer module makes (one writer per process).
static SIZE: AtomicUsize = AtomicUsize::new(64);
/// Whether the writer module fills a buffer its output lends (`ferroc-shm`).
static LEND: AtomicBool = AtomicBool::new(true);
/// Per value the reader saw: the latency and the part of it after the value arrived in
/// the reader's Zenoh callback (ns; 0 for the bare subscriber, which reads it there).
static SEEN: Mutex<Vec<(u64, u64)>> = Mutex::new(Vec::new());

/// Fills `data` with frame `seq` and stamps it last.
fn fill(data: &mut [u8], seq: u64) {
    data.fill(seq as u8);
    data[..8].copy_from_slice(&mono_ns().to_le_bytes());
}

pub(crate) fn stamp_of(data: &[u8]) -> Option<u64> {
    data.first_chunk::<8>().map(|b| u64::from_le_bytes(*b))
}

fn seen(latency: u64, hop: u64) {
    SEEN.lock()
        .unwrap_or_else(|e| e.into_inner())
        .push((latency, hop));
}

/// Publishes an image of `SIZE` bytes every cycle.
struct Camera {
    out: Out<Image>,
    seq: u64,
}
impl Module for Camera {
    fn update(&mut self) {
        self.seq += 1;
        let (seq, size) = (self.seq, SIZE.load(Ordering::Relaxed));
        let lend = LEND.load(Ordering::Relaxed);
        let out = &self.out;
        out.publish_with(|img| {
            img.width = size as u32;
            img.height = 1;
            img.step = size as u32;
            "mono8".clone_into(&mut img.encoding);
            if lend {
                out.lend_in(&mut img.data, size);
            } else {
                img.data.resize(size, 0);
            }
            fill(&mut img.data, seq);
        });
    }
}
impl ModuleType for Camera {
    const NAME: &'static str = "bench.Camera";
    fn create(m: &mut Setup<'_>) -> Self {
        Camera {
            out: m.output("out").build(),
            seq: 0,
        }
    }
}

/// Notes `now - stamp` of every image it reads.
struct Viewer {
    input: In<Image>,
}
impl Module for Viewer {
    fn update(&mut self) {
        if self.input.changed() {
            if let Some(stamp) = stamp_of(&self.input.get().data) {
                let hop = self.input.age().map_or(0, |a| a.as_nanos() as u64);
                seen(mono_ns().saturating_sub(stamp), hop);
            }
        }
    }
}
impl ModuleType for Viewer {
    const NAME: &'static str = "bench.Viewer";
    fn create(m: &mut Setup<'_>) -> Self {
        Viewer {
            input: m.input("in").build(),
        }
    }
}

const LINK: LinkSpec<'static> = LinkSpec {
    id: 0,
    from_part: "writer",
    to_part: "reader",
    model_type: "ferroc_std.Image",
    sharing: Sharing::OnChange {
        min_interval: Duration::ZERO,
    },
    reliable: true,
    deadline: None,
};

fn registry() -> Registry {
    let mut r = Registry::new();
    r.register::<Camera>().register::<Viewer>();
    ferroc_std::register(&mut r);
    r
}

/// The `--zenoh-config` of a variant: shared memory off for `…-net`.
pub(crate) fn config_of(variant: &str) -> Result<Option<PathBuf>, String> {
    if !variant.ends_with("-net") {
        return Ok(None);
    }
    let path = std::env::temp_dir().join(format!("ferroc-b4-large-{}.json5", std::process::id()));
    std::fs::write(
        &path,
        "{ transport: { shared_memory: { enabled: false } } }",
    )
    .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    Ok(Some(path))
}

/// How the reader's container waits for data (`--reader-wait`, handed to the reader
/// program in this variable; the writer's periodic container ignores it).
const WAIT_VAR: &str = "FERROC_B4_LARGE_READER_WAIT";

fn reader_wait() -> WaitMode {
    let wait = std::env::var(WAIT_VAR).ok();
    wait.and_then(|w| WaitMode::parse(&w)).unwrap_or_default()
}

/// One part of a ferroc variant: the camera every `gap`, or the viewer woken by data.
fn part(
    registry: &Registry,
    part: &str,
    (writer, reader): (&str, &str),
    config: Option<&PathBuf>,
    gap: Duration,
) -> Result<RunningApp, String> {
    let mut b = Builder::new(registry);
    let (path, type_name, schedule) = match part {
        "writer" => ("writer/camera", "bench.Camera", Schedule::Periodic(gap)),
        _ => ("reader/viewer", "bench.Viewer", Schedule::Data),
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
            wait: reader_wait(),
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
    let addresses = addresses(part, writer, reader);
    let network = Zenoh::new(APP, addresses, config.map(PathBuf::as_path))?;
    let options = StartOptions {
        network: Some(Arc::new(network)),
        ..StartOptions::default()
    };
    b.start_with(options).map_err(|e| e.to_string())
}

/// The reader: `b4-large-child VARIANT WRITER READER N` prints N latencies and the part
/// of each after the reader's Zenoh callback (ns) after the warm-up, a pair a line.
pub fn child(args: &[String]) -> u8 {
    let [variant, writer, reader, n] = args else {
        eprintln!("usage: {CHILD_ARG} VARIANT WRITER READER N");
        return 2;
    };
    let Ok(n) = n.parse::<usize>() else {
        eprintln!("{CHILD_ARG}: N must be a number");
        return 2;
    };
    // Zenoh's runtime threads as a part program has them (the bare reader too).
    ferroc_zenoh::config::runtime::use_default();
    let registry = registry();
    let mut keep: Vec<Box<dyn std::any::Any>> = Vec::new();
    let started = config_of(variant).and_then(|config| {
        if variant.starts_with("ferroc") {
            let app = part(
                &registry,
                "reader",
                (writer, reader),
                config.as_ref(),
                gap(0),
            )?;
            keep.push(Box::new(app));
            return Ok(());
        }
        let s = bare::session("reader", (writer, reader), config.as_deref())?;
        let sub = s
            .declare_subscriber(KEY)
            .callback(|sample| {
                let first = sample.payload().slices().next().and_then(stamp_of);
                if let Some(stamp) = first {
                    seen(mono_ns().saturating_sub(stamp), 0);
                }
            })
            .wait()
            .map_err(|e| e.to_string())?;
        keep.push(Box::new(sub));
        keep.push(Box::new(s));
        Ok(())
    });
    if let Err(e) = started {
        eprintln!("{CHILD_ARG}: {e}");
        return 1;
    }
    // Values come every 20 ms at most: one this late means the pair never connected
    // (seen once in ~20 runs); fail soon rather than wait out the writer's deadline.
    let (mut last, mut progress) = (0, Instant::now());
    // The reader's CPU (all its threads) and wall time from the end of the warm-up.
    let mut from: Option<(u64, u64)> = None;
    loop {
        let len = SEEN.lock().unwrap_or_else(|e| e.into_inner()).len();
        if len >= WARM_UP && from.is_none() {
            from = Some((cpu_ns(), mono_ns()));
        }
        if len >= WARM_UP + n {
            break;
        }
        if len > last {
            (last, progress) = (len, Instant::now());
        } else if progress.elapsed() > STALLED {
            eprintln!(
                "{CHILD_ARG}: no value for {} s ({len} arrived)",
                STALLED.as_secs()
            );
            return 1;
        }
        // As rarely as before the CPU figure was added: a poller waking more often
        // would keep the CPU from idling between values, which is what is measured.
        std::thread::sleep(Duration::from_millis(10));
    }
    let (cpu0, wall0) = from.unwrap_or_default();
    let (cpu, wall) = (cpu_ns() - cpu0, mono_ns() - wall0);
    let seen = std::mem::take(&mut *SEEN.lock().unwrap_or_else(|e| e.into_inner()));
    let mut out: String = seen[WARM_UP..WARM_UP + n]
        .iter()
        .map(|(latency, hop)| format!("{latency} {hop}\n"))
        .collect();
    out.push_str(&format!("cpu {cpu} {wall}\n"));
    print!("{out}");
    drop(keep);
    0
}

/// CPU time of this process, all threads (ns).
fn cpu_ns() -> u64 {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: writes one timespec.
    unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut t) };
    t.tv_sec as u64 * 1_000_000_000 + t.tv_nsec as u64
}

/// What one run of a variant measured: per value the latency and the part after the
/// Zenoh callback (ns); the reader's CPU and wall time over those values (ns).
type Measured = (Vec<(u64, u64)>, [u64; 2]);

/// One variant and size once: the reader as a child, the writer here until the child
/// is done. Per value: the latency and the part after the Zenoh callback (ns); and
/// the reader's CPU and wall time over those values (ns).
fn once(variant: &str, size: usize, n: u64) -> Result<Measured, String> {
    let (writer, reader) = (free_address()?, free_address()?);
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let mut child = Command::new(exe)
        .args([CHILD_ARG, variant, &writer, &reader, &n.to_string()])
        .env(WAIT_VAR, reader_wait().as_str())
        .stdout(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot start the reader: {e}"))?;
    let stdout = child.stdout.take().ok_or("no output of the reader")?;
    let reading = std::thread::spawn(move || {
        let (mut samples, mut cpu) = (Vec::new(), [0u64; 2]);
        for l in BufReader::new(stdout).lines().map_while(Result::ok) {
            let numbers: Vec<u64> = (l.split_whitespace())
                .filter_map(|w| w.parse().ok())
                .collect();
            match (l.starts_with("cpu "), &numbers[..]) {
                (true, &[c, w]) => cpu = [c, w],
                (false, &[latency, hop]) => samples.push((latency, hop)),
                _ => {}
            }
        }
        (samples, cpu)
    });
    let deadline = Instant::now() + Duration::from_secs(300);
    let mut done = || -> Result<bool, String> {
        if Instant::now() > deadline {
            let _ = child.kill();
            return Err("the reader did not finish".into());
        }
        Ok(child.try_wait().map_err(|e| e.to_string())?.is_some())
    };
    SIZE.store(size, Ordering::Relaxed);
    LEND.store(variant != "ferroc-copy", Ordering::Relaxed);
    if variant.starts_with("ferroc") {
        let config = config_of(variant)?;
        let registry = registry();
        let app = part(
            &registry,
            "writer",
            (&writer, &reader),
            config.as_ref(),
            gap(size),
        )?;
        while !done()? {
            std::thread::sleep(Duration::from_millis(5));
        }
        drop(app);
    } else {
        bare::writer(variant, (&writer, &reader), size, &mut done)?;
    }
    let status = child.wait().map_err(|e| e.to_string())?;
    let (samples, cpu) = reading.join().map_err(|_| "reading the reader failed")?;
    if !status.success() || samples.len() as u64 != n {
        return Err(format!(
            "the reader failed ({status}, {} values)",
            samples.len()
        ));
    }
    Ok((samples, cpu))
}

/// What one run measures: the values per size and variant, the rounds, the sizes and
/// the variants (`--sizes`, `--variants`: all by default).
struct Plan {
    messages: u64,
    rounds: u64,
    sizes: Vec<usize>,
    variants: [bool; 5],
}

fn plan(args: &[String]) -> Result<Plan, String> {
    let o = Options::parse(
        "b4-large",
        args,
        &["messages", "rounds", "sizes", "variants", "reader-wait"],
        &[],
    )?;
    let sizes = match o.text("sizes") {
        None => SIZES.to_vec(),
        Some(list) => (list.split(','))
            .map(|s| match s.trim().parse::<usize>() {
                Ok(n) if SIZES.contains(&n) => Ok(n),
                _ => Err(format!("b4-large: --sizes {s}: one of {SIZES:?}")),
            })
            .collect::<Result<_, _>>()?,
    };
    if let Some(w) = o.text("reader-wait") {
        if WaitMode::parse(w).is_none() {
            return Err(format!(
                "b4-large: --reader-wait {w}: park, spin, adaptive or inline"
            ));
        }
        // Read back by `reader_wait` here and, through the environment, in the reader.
        std::env::set_var(WAIT_VAR, w);
    }
    let mut variants = [o.text("variants").is_none(); 5];
    for name in o.text("variants").unwrap_or_default().split(',') {
        let name = name.trim();
        match VARIANTS.iter().position(|v| *v == name) {
            Some(i) => variants[i] = true,
            None if name.is_empty() => {}
            None => return Err(format!("b4-large: --variants {name}: one of {VARIANTS:?}")),
        }
    }
    Ok(Plan {
        messages: o.number("messages", DEFAULT_MESSAGES, 1, 1_000_000)?,
        rounds: o.number("rounds", DEFAULT_ROUNDS, 1, 100)?,
        sizes,
        variants,
    })
}

/// Runs B4 across parts with large values and prints its lines; the exit code.
pub fn run(args: &[String]) -> u8 {
    let Plan {
        messages,
        rounds,
        sizes,
        variants,
    } = match plan(args) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("{e}");
            return 2;
        }
    };
    // Zenoh's runtime threads as a part program has them, in the writers here and
    // (inherited) in the readers; the environment's `ZENOH_RUNTIME` wins.
    let runtime = match ferroc_zenoh::config::runtime::use_default() {
        Some(ours) => format!("ZENOH_RUNTIME='{ours}' (ferroc's, as in a bundle)"),
        None => format!(
            "ZENOH_RUNTIME='{}' (the environment's)",
            std::env::var(ferroc_zenoh::config::runtime::ENV).unwrap_or_default()
        ),
    };
    if cfg!(debug_assertions) {
        println!("b4-large: warning: not a release build; figures are meaningless");
    }
    let per_round = messages.div_ceil(rounds.min(messages));
    println!(
        "b4-large: {} values per size and variant between two programs on 127.0.0.1 \
         ({rounds} rounds, +{WARM_UP} warm-up each; 64 B and 64 KB every 2 ms, 1 MB every \
         10 ms, 6.2 MB every 20 ms); every program {runtime}, ferroc's Zenoh configuration \
         of its part (the bare pair too: the writer connects, the reader listens); {}",
        per_round * rounds,
        load_note()
    );
    let mut result = Vec::new();
    for size in sizes {
        let mut samples: [Vec<(u64, u64)>; 5] = Default::default();
        let mut cpu = [[0u64; 2]; 5];
        for round in 0..rounds as usize {
            for k in 0..VARIANTS.len() {
                let i = (round + k) % VARIANTS.len();
                if !variants[i] {
                    continue;
                }
                let what = format!("b4-large: {} {size} B", VARIANTS[i]);
                match crate::b4_parts::retried(&what, || once(VARIANTS[i], size, per_round)) {
                    Ok((mut s, [c, w])) => {
                        samples[i].append(&mut s);
                        cpu[i] = [cpu[i][0] + c, cpu[i][1] + w];
                    }
                    Err(e) => {
                        eprintln!("b4-large: {} {size} B: {e}", VARIANTS[i]);
                        return 1;
                    }
                }
            }
        }
        let p50s = report(size, samples, cpu);
        let figures = (VARIANTS.iter().zip(p50s)).filter_map(|(v, p50)| {
            let v = v.replace('-', "_");
            p50.map(|p| format!("s{size}_{v}_p50_us={p:.1}"))
        });
        result.extend(figures);
    }
    println!("RESULT b4-large {}", result.join(" "));
    0
}

/// Prints one size's lines; the p50 of each variant measured (µs). For ferroc's
/// variants also the split at the reader's Zenoh callback: the way there (latency
/// minus `In::age`) and the hand-off to the reader's container after it.
fn report(size: usize, samples: [Vec<(u64, u64)>; 5], cpu: [[u64; 2]; 5]) -> [Option<f64>; 5] {
    let mut p50s = [None; 5];
    for (i, s) in samples.into_iter().enumerate() {
        let n = s.len();
        if n == 0 {
            continue;
        }
        let to_callback = s.iter().map(|(l, h)| l.saturating_sub(*h)).collect();
        let hop = s.iter().map(|(_, h)| *h).collect();
        let (p50, p99, max) = percentiles(s.into_iter().map(|(l, _)| l).collect());
        p50s[i] = Some(p50);
        println!(
            "b4-large {size:>8} B  {:<10}  p50 {p50:9.1}  p99 {p99:9.1}  max {max:9.1} µs  n={n}",
            VARIANTS[i]
        );
        let [c, w] = cpu[i];
        println!(
            "b4-large {size:>8} B  {:<10}  reader CPU {:.1} µs a value, {:.1} % of a core",
            VARIANTS[i],
            c as f64 / 1e3 / n as f64,
            100.0 * c as f64 / w.max(1) as f64
        );
        if VARIANTS[i].starts_with("ferroc") {
            let ((c50, c99, _), (h50, h99, _)) = (percentiles(to_callback), percentiles(hop));
            println!(
                "b4-large {size:>8} B  {:<10}  to callback p50 {c50:.1} p99 {c99:.1}, \
                 callback → module p50 {h50:.1} p99 {h99:.1} µs",
                VARIANTS[i]
            );
        }
    }
    let ratio = |a: usize, b: usize| match (p50s[a], p50s[b]) {
        (Some(a), Some(b)) => format!("{:.2}", a / b),
        _ => "-".into(),
    };
    println!(
        "b4-large {size:>8} B  ferroc-shm / zenoh-shm p50 {}, ferroc-copy / ferroc-shm p50 \
         {}, ferroc-net / ferroc-shm p50 {}",
        ratio(0, 3),
        ratio(1, 0),
        ratio(2, 0)
    );
    p50s
}
