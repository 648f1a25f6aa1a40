//! The programs of one B3-across-parts configuration, each a child process of the
//! benchmark: the producer (part `camera`) and the consumers (parts `c1`…`cN`), in
//! ferroc's two variants (a bundle's part program as the Builder makes it) and the
//! bare Zenoh one.
//!
//! What they print on stdout is the protocol with the parent (`super::once`):
//! a consumer prints `READY` once it listens, then, when its window ended,
//! `SEEN frames=… fps=… missed=… last=… all=… shared=…` (`all` frames seen, the
//! warm-up's too, `shared` of them in shared memory) and `LAT ns ns …`; the producer
//! prints `START` before it publishes the first measured frame and `END` after the
//! last, and stops when its stdin closes.

use super::{FRAME_BYTES, PERIOD, WARM_UP};
use crate::b4_large::stamp_of;
use crate::b4_parts::mono_ns;
use ferroc_runtime::builder::{
    Builder, Conversion, ModuleSpec, Registry, RunningApp, Schedule, StartOptions, StepKind,
    ThreadSpec,
};
use ferroc_runtime::container::ThreadOptions;
use ferroc_runtime::link::transport::{Addresses, PartLinks, Sending};
use ferroc_runtime::link::{LinkSpec, Sharing};
use ferroc_runtime::module::{In, Module, ModuleType, Out, Setup};
use ferroc_runtime::port::ConnectOptions;
use ferroc_std::Image;
use ferroc_zenoh::config::{ModelShm, PartConfig};
use ferroc_zenoh::free::Qos;
use ferroc_zenoh::Zenoh;
use std::io::Write;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};
use zenoh::shm::{BlockOn, GarbageCollect, ShmProviderBuilder};
use zenoh::Wait;

const APP: &str = "b3parts";
const KEY: &str = "bench/b3parts/bare";
/// A consumer that saw measured frames and then none for this long is done (the
/// producer stopped, or the last frames were dropped).
const QUIET: Duration = Duration::from_secs(3);

/// Measured frames per configuration (set once in each child).
static FRAMES: AtomicU64 = AtomicU64::new(0);

/// What a consumer saw of the measured frames (sequence numbers after the warm-up).
#[derive(Default)]
struct Seen {
    latencies: Vec<u64>,
    first_ns: u64,
    last_ns: u64,
    last_seq: u64,
    missed: u64,
    /// Every frame seen, the warm-up's too; of those, the ones that came in shared
    /// memory (bare: counted here; ferroc: its network's count, at the end).
    all: u64,
    shared: u64,
}
static SEEN: Mutex<Seen> = Mutex::new(Seen {
    latencies: Vec::new(),
    first_ns: 0,
    last_ns: 0,
    last_seq: 0,
    missed: 0,
    all: 0,
    shared: 0,
});
/// Notified when the window's last frame was seen: the consumer's main thread sleeps
/// on it instead of polling (a poll is the harness's CPU, not what is measured).
static LAST_SEEN: Condvar = Condvar::new();

fn seen() -> std::sync::MutexGuard<'static, Seen> {
    SEEN.lock().unwrap_or_else(|e| e.into_inner())
}

/// Notes frame `data` (stamp in bytes 0..8, sequence number in 8..16); `shared`:
/// it came in shared memory (bare), `None` when the network counts it (ferroc).
fn saw(data: &[u8], shared: Option<bool>) {
    let now = mono_ns();
    let (Some(stamp), Some(seq)) = (stamp_of(data), data.get(8..).and_then(stamp_of)) else {
        return;
    };
    let mut s = seen();
    s.all += 1;
    s.shared += u64::from(shared == Some(true));
    if seq <= WARM_UP {
        return;
    }
    if s.latencies.is_empty() {
        s.first_ns = now;
    } else if seq > s.last_seq + 1 {
        s.missed += seq - s.last_seq - 1;
    }
    s.latencies.push(now.saturating_sub(stamp));
    s.last_ns = now;
    s.last_seq = s.last_seq.max(seq);
    if seq >= WARM_UP + FRAMES.load(Ordering::Relaxed) {
        LAST_SEEN.notify_all();
    }
}

/// The source frame the producer copies each cycle (as the in-process B3 does).
fn source_frame() -> Vec<u8> {
    (0..FRAME_BYTES).map(|i| (i % 251) as u8).collect()
}

/// Copies the source into `data`, then writes `seq` and, last, the stamp.
fn frame_into(data: &mut [u8], source: &[u8], seq: u64) {
    data.copy_from_slice(source);
    data[8..16].copy_from_slice(&seq.to_le_bytes());
    data[..8].copy_from_slice(&mono_ns().to_le_bytes());
}

/// Tells the parent where the measured window starts and ends (by sequence number).
fn announce(seq: u64, after: bool) {
    let frames = FRAMES.load(Ordering::Relaxed);
    let line = match (after, seq) {
        (false, s) if s == WARM_UP + 1 => "START",
        (true, s) if s == WARM_UP + frames => "END",
        _ => return,
    };
    let mut out = std::io::stdout().lock();
    let _ = writeln!(out, "{line}");
    let _ = out.flush();
}

/// The camera of the ferroc variants: a 1080p RGB frame every cycle.
struct Camera {
    out: Out<Image>,
    source: Vec<u8>,
    seq: u64,
}
impl Module for Camera {
    fn update(&mut self) {
        self.seq += 1;
        let seq = self.seq;
        announce(seq, false);
        let (source, out) = (&self.source, &self.out);
        out.publish_with(|img| {
            (img.width, img.height, img.step) = (1920, 1080, 1920 * 3);
            "rgb8".clone_into(&mut img.encoding);
            // The frame straight into the pool buffer it travels in (`Out::lend`).
            out.lend_in(&mut img.data, FRAME_BYTES);
            frame_into(&mut img.data, source, seq);
        });
        announce(seq, true);
    }
}
impl ModuleType for Camera {
    const NAME: &'static str = "bench.B3Camera";
    fn create(m: &mut Setup<'_>) -> Self {
        Camera {
            out: m.output("out").build(),
            source: source_frame(),
            seq: 0,
        }
    }
}

/// A consumer of the ferroc variants: reads the frame in its step.
struct Viewer {
    input: In<Image>,
}
impl Module for Viewer {
    fn update(&mut self) {
        if self.input.changed() {
            saw(&self.input.get().data, None);
        }
    }
}
impl ModuleType for Viewer {
    const NAME: &'static str = "bench.B3Viewer";
    fn create(m: &mut Setup<'_>) -> Self {
        Viewer {
            input: m.input("in").build(),
        }
    }
}

fn part_name(index: usize) -> String {
    if index == 0 {
        "camera".into()
    } else {
        format!("c{index}")
    }
}

/// The link to consumer `index`: what a bundle makes of a latest-value input in
/// another part (not reliable: a congested link keeps the newest frame).
fn link(index: usize, to_part: &str) -> LinkSpec<'_> {
    LinkSpec {
        id: index as u32,
        from_part: "camera",
        to_part,
        model_type: "ferroc_std.Image",
        sharing: Sharing::OnChange {
            min_interval: Duration::ZERO,
        },
        reliable: false,
        deadline: None,
    }
}

/// The addresses of part `index`: the producer knows every consumer, a consumer only
/// the producer (no mesh of consumers).
fn addresses(index: usize, all: &[String]) -> Addresses {
    let part = part_name(index);
    let peers = (all.iter().enumerate())
        .filter(|(i, _)| index == 0 || *i == 0 || *i == index)
        .map(|(i, a)| (part_name(i), a.clone()))
        .collect();
    Addresses {
        part,
        listen: all[index].clone(),
        peers,
    }
}

/// Part `index` of a ferroc variant, started; and its network.
fn ferroc_part(
    variant: &str,
    index: usize,
    all: &[String],
) -> Result<(RunningApp, Arc<Zenoh>), String> {
    let mut registry = Registry::new();
    registry.register::<Camera>().register::<Viewer>();
    ferroc_std::register(&mut registry);
    let part = part_name(index);
    let path = format!("{part}/{}", if index == 0 { "camera" } else { "viewer" });
    let mut b = Builder::new(&registry);
    let spec = ModuleSpec {
        path: &path,
        type_name: if index == 0 {
            Camera::NAME
        } else {
            Viewer::NAME
        },
        params: &[],
        queues: &[],
        ports: &[],
        violations: Default::default(),
    };
    b.add_module(spec).map_err(|e| e.to_string())?;
    let schedule = match index {
        0 => Schedule::Periodic(PERIOD),
        _ => Schedule::Data,
    };
    let options = ThreadOptions {
        // The consumer's container; the producer's is periodic and ignores it.
        wait: super::consumer_wait(),
        ..ThreadOptions::default()
    };
    b.add_thread(ThreadSpec {
        path: part.clone(),
        schedule,
        options,
        steps: vec![(path.clone(), StepKind::Update)],
    })
    .map_err(|e| e.to_string())?;
    let names: Vec<String> = (0..all.len()).map(part_name).collect();
    if index == 0 {
        for (i, name) in names.iter().enumerate().skip(1) {
            let out = (path.as_str(), "out");
            (b.link_out(&link(i, name), out, Conversion::default())).map_err(|e| e.to_string())?;
        }
    } else {
        let input = (path.as_str(), "in");
        (b.link_in(
            &link(index, &names[index]),
            input,
            ConnectOptions::default(),
        ))
        .map_err(|e| e.to_string())?;
    }
    let config = config_of(variant)?;
    let network = Arc::new(Zenoh::new(APP, addresses(index, all), config.as_deref())?);
    let options = StartOptions {
        network: Some(Arc::clone(&network) as _),
        ..StartOptions::default()
    };
    let app = b.start_with(options).map_err(|e| e.to_string())?;
    Ok((app, network))
}

/// A bare Zenoh session of part `index`: ferroc's configuration of the same part
/// (who connects to whom included), as `b4-large` uses.
fn bare_session(variant: &str, index: usize, all: &[String]) -> Result<zenoh::Session, String> {
    let file = config_of(variant)?;
    let addresses = addresses(index, all);
    let part = PartConfig::new(&addresses, file.as_deref(), ModelShm::default())?;
    let config = part.for_links(&addresses, &part_links(index, all.len()))?;
    zenoh::open(config).wait().map_err(|e| e.to_string())
}

/// What part `index` sends and receives, as ferroc's part of the same index.
fn part_links(index: usize, parts: usize) -> PartLinks {
    let mut links = PartLinks {
        part: part_name(index),
        ..PartLinks::default()
    };
    if index == 0 {
        for i in 1..parts {
            let spec = link(i, "");
            let sending = Sending {
                to_part: part_name(i),
                topic: "camera/camera/out".into(),
                model_type: spec.model_type.into(),
                sharing: spec.sharing,
                reliable: spec.reliable,
            };
            links.sending.insert(i as u32, sending);
        }
    } else {
        links.receiving.insert(index as u32, part_name(0));
    }
    links
}

/// The bare producer: a frame every period in a buffer of its own `ShmProvider`, one
/// put for every subscriber (Zenoh fans it out), with the QoS ferroc gives the link,
/// until `stop`.
fn bare_producer(all: &[String], stop: &AtomicBool) -> Result<(), String> {
    let s = bare_session("zenoh-shm", 0, all)?;
    let qos = Qos::of(&Sending {
        to_part: part_name(1),
        topic: "camera/camera/out".into(),
        model_type: "ferroc_std.Image".into(),
        sharing: link(1, "c1").sharing,
        reliable: false,
    });
    let publisher = (s.declare_publisher(KEY))
        .congestion_control(qos.congestion)
        .express(qos.express)
        .wait()
        .map_err(|e| e.to_string())?;
    let provider = ShmProviderBuilder::default_backend(ferroc_zenoh::shm::POOL_SIZE)
        .wait()
        .map_err(|e| e.to_string())?;
    let source = source_frame();
    let (mut next, mut seq) = (Instant::now(), 0u64);
    while !stop.load(Ordering::Relaxed) {
        // One sleep to the next frame's time, as ferroc's periodic container sleeps
        // (a poll every 200 µs cost this program ~5 % of a core for nothing).
        std::thread::sleep(next.saturating_duration_since(Instant::now()));
        next += PERIOD;
        seq += 1;
        announce(seq, false);
        let mut buf = (provider.alloc(FRAME_BYTES))
            .with_policy::<BlockOn<GarbageCollect>>()
            .wait()
            .map_err(|e| e.to_string())?;
        frame_into(&mut buf[..], &source, seq);
        publisher.put(buf).wait().map_err(|e| e.to_string())?;
        announce(seq, true);
    }
    Ok(())
}

/// `b3-parts-child VARIANT INDEX FRAMES ADDR0 ADDR1 …`: part `INDEX` (0 the producer)
/// of a configuration whose parts listen on `ADDR0…`.
pub fn child(args: &[String]) -> u8 {
    let parsed = match args {
        [variant, index, frames, all @ ..] if all.len() >= 2 => {
            (index.parse::<usize>().ok().filter(|i| *i < all.len()))
                .zip(frames.parse::<u64>().ok())
                .map(|(i, f)| (variant.as_str(), i, f, all))
        }
        _ => None,
    };
    let Some((variant, index, frames, all)) = parsed else {
        eprintln!("usage (internal to b3-parts): VARIANT INDEX FRAMES ADDR0 ADDR1 …");
        return 2;
    };
    FRAMES.store(frames, Ordering::Relaxed);
    // Zenoh's runtime threads as a bundle's part program has them (unless
    // `--zenoh-runtime` set them): the bare programs too, the same configuration.
    ferroc_zenoh::config::runtime::use_default();
    let done = if index == 0 {
        producer(variant, all)
    } else {
        consumer(variant, index, all)
    };
    match done {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("b3-parts {} ({variant}): {e}", part_name(index));
            1
        }
    }
}

/// Runs the producer until its stdin closes.
fn producer(variant: &str, all: &[String]) -> Result<(), String> {
    let until_stdin_closes = || {
        let _ = std::io::copy(&mut std::io::stdin().lock(), &mut std::io::sink());
    };
    if variant.starts_with("ferroc") {
        let (app, _network) = ferroc_part(variant, 0, all)?;
        // Blocked in `read` (a poll of a stop flag every 20 ms cost this program 50
        // wakeups a second that the bare producer does not make).
        until_stdin_closes();
        drop(app);
        return Ok(());
    }
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    std::thread::spawn(move || {
        until_stdin_closes();
        flag.store(true, Ordering::Relaxed);
    });
    bare_producer(all, &stop)
}

/// Runs consumer `index` until it saw the last measured frame (or none came for
/// [`QUIET`]), then prints what it saw.
fn consumer(variant: &str, index: usize, all: &[String]) -> Result<(), String> {
    let mut keep: Vec<Box<dyn std::any::Any>> = Vec::new();
    let mut network = None;
    if variant.starts_with("ferroc") {
        let (app, zenoh) = ferroc_part(variant, index, all)?;
        keep.push(Box::new(app));
        network = Some(zenoh);
    } else {
        let s = bare_session(variant, index, all)?;
        let sub = (s.declare_subscriber(KEY))
            .callback(|sample| {
                // The frame in place: one piece in shared memory.
                let shared = sample.payload().as_shm().is_some();
                if let Some(first) = sample.payload().slices().next() {
                    saw(first, Some(shared));
                }
            })
            .wait()
            .map_err(|e| e.to_string())?;
        keep.push(Box::new(sub));
        keep.push(Box::new(s));
    }
    println!("READY");
    let _ = std::io::stdout().flush();
    wait_for_window_end()?;
    let mut s = std::mem::take(&mut *seen());
    if let Some(network) = network {
        s.shared = network.shm_use().received_shared;
    }
    let span = s.last_ns.saturating_sub(s.first_ns) as f64 / 1e9;
    let fps = (s.latencies.len().saturating_sub(1)) as f64 / span.max(1e-9);
    let lat: Vec<String> = s.latencies.iter().map(u64::to_string).collect();
    let mut out = std::io::stdout().lock();
    let _ = writeln!(
        out,
        "SEEN frames={} fps={fps:.3} missed={} last={} all={} shared={}\nLAT {}",
        s.latencies.len(),
        s.missed,
        s.last_seq,
        s.all,
        s.shared,
        lat.join(" ")
    );
    let _ = out.flush();
    drop(keep);
    Ok(())
}

/// Waits until the last measured frame arrived, measured frames stopped coming, or
/// the window lasted twice its time at 50 fps (a producer that cannot keep the rate:
/// the figures then cover fewer frames, and the fps say so).
fn wait_for_window_end() -> Result<(), String> {
    let frames = FRAMES.load(Ordering::Relaxed);
    let window = (PERIOD * (2 * frames) as u32).as_nanos() as u64;
    // The warm-up at a few frames per second, plus start-up on a loaded machine.
    let limit = PERIOD * (25 * WARM_UP) as u32 + Duration::from_secs(60);
    let deadline = Instant::now() + limit;
    let mut s = seen();
    loop {
        // Woken by the window's last frame, else once a second for the other ends: a
        // poll every 100 ms was 2–4 µs of a consumer's CPU a frame (h30c's per-thread
        // figures), the harness's and not what is measured.
        s = match LAST_SEEN.wait_timeout(s, Duration::from_secs(1)) {
            Ok((s, _)) => s,
            Err(e) => e.into_inner().0,
        };
        let now = mono_ns();
        let measuring = !s.latencies.is_empty();
        let quiet = now.saturating_sub(s.last_ns) > QUIET.as_nanos() as u64;
        let long = now.saturating_sub(s.first_ns) > window;
        if s.last_seq >= WARM_UP + frames || (measuring && (quiet || long)) {
            return Ok(());
        }
        if !measuring && Instant::now() > deadline {
            return Err(format!(
                "no measured frame arrived in {} s",
                limit.as_secs()
            ));
        }
    }
}

/// The `--zenoh-config` of a program of `variant`: shared memory off for `…-net`,
/// Zenoh's gossip autoconnect with `--mesh on` (super::MESH_ENV), the `--zenoh`
/// settings (super::ZENOH_ENV); none when nothing is set.
fn config_of(variant: &str) -> Result<Option<std::path::PathBuf>, String> {
    let mesh = std::env::var(super::MESH_ENV).is_ok_and(|m| m == "on");
    let mut settings: Vec<(String, String)> = Vec::new();
    if variant.ends_with("-net") {
        settings.push(("transport/shared_memory/enabled".into(), "false".into()));
    }
    if mesh {
        let zenohs = "{ router: [], peer: [\"router\", \"peer\"] }";
        settings.push(("scouting/gossip/autoconnect".into(), zenohs.into()));
    }
    let extra = std::env::var(super::ZENOH_ENV).unwrap_or_default();
    for pair in extra.split(';').filter(|p| !p.trim().is_empty()) {
        let (key, value) =
            (pair.split_once('=')).ok_or_else(|| format!("--zenoh `{pair}`: write KEY=VALUE"))?;
        settings.push((key.trim().into(), value.trim().into()));
    }
    if settings.is_empty() {
        return Ok(None);
    }
    let path = std::env::temp_dir().join(format!("ferroc-b3-parts-{}.json5", std::process::id()));
    std::fs::write(&path, json5_of(&settings))
        .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    Ok(Some(path))
}

/// A JSON5 object of `key/path` = value settings (values written as given).
fn json5_of(settings: &[(String, String)]) -> String {
    use std::collections::BTreeMap;
    enum Node {
        Value(String),
        Object(BTreeMap<String, Node>),
    }
    fn put(object: &mut BTreeMap<String, Node>, path: &[&str], value: &str) {
        match path {
            [] => {}
            [last] => {
                object.insert(last.to_string(), Node::Value(value.into()));
            }
            [first, rest @ ..] => {
                let node = (object.entry(first.to_string()))
                    .or_insert_with(|| Node::Object(BTreeMap::new()));
                if let Node::Value(_) = node {
                    *node = Node::Object(BTreeMap::new());
                }
                if let Node::Object(inner) = node {
                    put(inner, rest, value);
                }
            }
        }
    }
    fn text(object: &BTreeMap<String, Node>) -> String {
        let fields: Vec<String> = (object.iter())
            .map(|(k, v)| match v {
                Node::Value(value) => format!("{k}: {value}"),
                Node::Object(inner) => format!("{k}: {}", text(inner)),
            })
            .collect();
        format!("{{ {} }}", fields.join(", "))
    }
    let mut root = BTreeMap::new();
    for (key, value) in settings {
        put(&mut root, &key.split('/').collect::<Vec<_>>(), value);
    }
    text(&root)
}
