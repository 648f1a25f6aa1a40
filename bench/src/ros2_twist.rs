//! `ros2-twist` — latency of a `geometry_msgs/msg/Twist` between two part programs as
//! a ROS 2 topic (issue 29) against the same value through a plain ferroc link, over
//! the same two Zenoh sessions on 127.0.0.1 in the same run.
//!
//! The writer is this process, the reader a child process (`ferroc-bench
//! ros2-twist-child`), as in `b4-parts` (whose helpers this uses).
//!
//! * `link`: part `writer`'s module publishes a Twist every `--gap-us`; a ferroc link
//!   (postcard, reliable) carries it to part `reader`, whose data-triggered module
//!   computes `now - stamp`.
//! * `ros2`: the same parts are ROS 2 nodes (`bench_writer`, `bench_reader`): the output
//!   is published as `/bench_twist` (rmw_zenoh's key, attachment and the message's CDR
//!   written straight from the value, `Codec::ros2_encode`) and the input subscribed
//!   from it (`ros2_decode`), with ROS 2's default QoS (reliable, keep last 10).
//!
//! The stamp (`CLOCK_MONOTONIC` ns, taken just before publishing) travels in
//! `linear.x` as a float64 (exact below 2^53 ns, about 104 days of uptime), the
//! sequence number in `linear.y`: a real Twist of 48 bytes, nothing added.

use crate::b3::load_note;
use crate::b4_parts::{addresses, free_address, mono_ns, percentiles, retried};
use crate::options::Options;
use ferroc_runtime::builder::{
    Builder, Conversion, ModuleSpec, Registry, RunningApp, Schedule, StartOptions, StepKind,
    ThreadSpec,
};
use ferroc_runtime::container::ThreadOptions;
use ferroc_runtime::link::ros2::{Ros2Node, Ros2Qos, Ros2Topic};
use ferroc_runtime::link::{LinkSpec, Sharing};
use ferroc_runtime::module::{In, Module, ModuleType, Out, Setup};
use ferroc_runtime::port::{ConnectOptions, NoUninit, WaitMode};
use ferroc_zenoh::Zenoh;
use serde::{Deserialize, Serialize};
use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// The argument that makes `ferroc-bench` the reader.
pub const CHILD_ARG: &str = "ros2-twist-child";
const APP: &str = "ros2twist";
const WARM_UP: u64 = 500;
const DEFAULT_MESSAGES: u64 = 40_000;
const DEFAULT_GAP_US: u64 = 200;
const DEFAULT_ROUNDS: u64 = 4;

#[repr(C)]
#[derive(Clone, Copy, Default, Debug, Serialize, Deserialize)]
struct Vector3 {
    x: f64,
    y: f64,
    z: f64,
}

/// A library type with Twist's fields (what check R102 accepts as the message).
#[repr(C)]
#[derive(Clone, Copy, Default, Debug, Serialize, Deserialize)]
pub struct Twist {
    linear: Vector3,
    angular: Vector3,
}
// SAFETY: `repr(C)`, six `f64` in a row: no padding.
unsafe impl NoUninit for Twist {}
ferroc_runtime::port_value!(Twist, "bench.Twist", copy);

static GAP_NS: AtomicU64 = AtomicU64::new(200_000);

/// Writes one Twist every gap, stamped just before publishing.
struct Source {
    out: Out<Twist>,
    next: Option<Instant>,
    seq: u64,
}
impl Module for Source {
    fn update(&mut self) {
        let gap = Duration::from_nanos(GAP_NS.load(Ordering::Relaxed));
        let next = *self.next.get_or_insert_with(Instant::now);
        while Instant::now() < next {
            std::hint::spin_loop();
        }
        self.next = Some(next + gap);
        self.seq += 1;
        let seq = self.seq as f64;
        self.out.publish_with(|t| {
            t.linear.y = seq;
            t.angular.z = 0.25;
            t.linear.x = mono_ns() as f64;
        });
    }
}
impl ModuleType for Source {
    const NAME: &'static str = "bench.TwistSource";
    fn create(m: &mut Setup<'_>) -> Self {
        Source {
            out: m.output("out").build(),
            next: None,
            seq: 0,
        }
    }
}

/// Latencies (ns) of the values read.
static SEEN: Mutex<Vec<u64>> = Mutex::new(Vec::new());

struct Sink {
    input: In<Twist>,
}
impl Module for Sink {
    fn update(&mut self) {
        if self.input.changed() {
            let stamp = self.input.get().linear.x as u64;
            let latency = mono_ns().saturating_sub(stamp);
            SEEN.lock().unwrap_or_else(|e| e.into_inner()).push(latency);
        }
    }
}
impl ModuleType for Sink {
    const NAME: &'static str = "bench.TwistSink";
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
    model_type: "bench.Twist",
    sharing: Sharing::OnChange {
        min_interval: Duration::ZERO,
    },
    reliable: true,
    deadline: None,
};

fn registry() -> Registry {
    let mut r = Registry::new();
    r.register::<Source>().register::<Sink>();
    r.register_serde::<Twist>();
    r
}

/// The part `part` as a ROS 2 node publishing or subscribing `/bench_twist`.
fn node(part: &str, port: &str) -> Ros2Node {
    let publish = part == "writer";
    Ros2Node {
        part: part.into(),
        domain: 0,
        namespace: "/".into(),
        name: format!("bench_{part}"),
        topics: vec![Ros2Topic {
            id: 0,
            publish,
            port: (port.into(), if publish { "out" } else { "in" }.into()),
            model_type: "bench.Twist".into(),
            topic: "/bench_twist".into(),
            message: "geometry_msgs/msg/Twist".into(),
            field: None,
            qos: Ros2Qos::default(),
            frame_id: String::new(),
        }],
        services: Vec::new(),
        clients: Vec::new(),
        interfaces: Vec::new(),
    }
}

/// One part of variant `variant` (`link` or `ros2`), running freely.
fn part(
    registry: &Registry,
    variant: &str,
    part: &str,
    writer: &str,
    reader: &str,
) -> Result<RunningApp, String> {
    let mut b = Builder::new(registry);
    let (path, type_name, schedule) = match part {
        "writer" => ("writer/source", "bench.TwistSource", Schedule::Continuous),
        _ => ("reader/sink", "bench.TwistSink", Schedule::Data),
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
            wait: WaitMode::Park,
            ..ThreadOptions::default()
        },
        steps: vec![(path.into(), StepKind::Update)],
    })
    .map_err(|e| e.to_string())?;
    match (variant, part) {
        ("ros2", _) => b.ros2_node(node(part, path)),
        (_, "writer") => b.link_out(&LINK, (path, "out"), Conversion::default()),
        _ => b.link_in(&LINK, (path, "in"), ConnectOptions::default()),
    }
    .map_err(|e| e.to_string())?;
    let network = Zenoh::new(APP, addresses(part, writer, reader), None)?;
    let options = StartOptions {
        network: Some(Arc::new(network)),
        ..StartOptions::default()
    };
    b.start_with(options).map_err(|e| e.to_string())
}

/// The reader: `ros2-twist-child VARIANT WRITER READER N` prints N latencies (ns), one
/// a line, after the warm-up.
pub fn child(args: &[String]) -> u8 {
    let [variant, writer, reader, n] = args else {
        eprintln!("usage: {CHILD_ARG} link|ros2 WRITER READER N");
        return 2;
    };
    let Ok(n) = n.parse::<u64>() else {
        eprintln!("{CHILD_ARG}: N must be a number");
        return 2;
    };
    let wanted = (WARM_UP + n) as usize;
    let app = match part(&registry(), variant, "reader", writer, reader) {
        Ok(app) => app,
        Err(e) => {
            eprintln!("{CHILD_ARG}: {e}");
            return 1;
        }
    };
    let deadline = Instant::now() + Duration::from_secs(300);
    while SEEN.lock().unwrap_or_else(|e| e.into_inner()).len() < wanted {
        if Instant::now() > deadline {
            eprintln!("{CHILD_ARG}: too few values arrived");
            return 1;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    let seen = std::mem::take(&mut *SEEN.lock().unwrap_or_else(|e| e.into_inner()));
    let out: String = seen[WARM_UP as usize..wanted]
        .iter()
        .map(|l| format!("{l}\n"))
        .collect();
    print!("{out}");
    drop(app);
    0
}

/// One variant once: the reader as a child, the writer here until the child is done.
fn once(variant: &str, n: u64, gap: Duration) -> Result<Vec<u64>, String> {
    let (writer, reader) = (free_address()?, free_address()?);
    let exe = std::env::current_exe().map_err(|e| e.to_string())?;
    let mut child = Command::new(exe)
        .args([CHILD_ARG, variant, &writer, &reader, &n.to_string()])
        .stdout(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot start the reader: {e}"))?;
    GAP_NS.store(gap.as_nanos() as u64, Ordering::Relaxed);
    let app = part(&registry(), variant, "writer", &writer, &reader)?;
    let stdout = child.stdout.take().ok_or("no output of the reader")?;
    let reading = std::thread::spawn(move || {
        BufReader::new(stdout)
            .lines()
            .map_while(Result::ok)
            .filter_map(|l| l.trim().parse::<u64>().ok())
            .collect::<Vec<u64>>()
    });
    let deadline = Instant::now() + Duration::from_secs(300);
    while child.try_wait().map_err(|e| e.to_string())?.is_none() {
        if Instant::now() > deadline {
            let _ = child.kill();
            return Err("the reader did not finish".into());
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    drop(app);
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

/// Runs the benchmark and prints its lines. Returns the process exit code.
pub fn run(args: &[String]) -> u8 {
    let parsed = Options::parse("ros2-twist", args, &["messages", "gap-us", "rounds"], &[])
        .and_then(|o| {
            Ok((
                o.number("messages", DEFAULT_MESSAGES, 1, 100_000_000)?,
                o.number("gap-us", DEFAULT_GAP_US, 1, 1_000_000)?,
                o.number("rounds", DEFAULT_ROUNDS, 1, 1000)?,
            ))
        });
    let (messages, gap_us, rounds) = match parsed {
        Ok(v) => v,
        Err(e) => {
            eprintln!("{e}");
            return 2;
        }
    };
    if cfg!(debug_assertions) {
        println!("ros2-twist: warning: not a release build; figures are meaningless");
    }
    let per_round = messages.div_ceil(rounds.min(messages));
    println!(
        "ros2-twist: {} Twists per variant between two programs over Zenoh on 127.0.0.1 \
         ({rounds} rounds, +{WARM_UP} warm-up each), one every {gap_us} µs; {}",
        per_round * rounds,
        load_note()
    );
    let gap = Duration::from_micros(gap_us);
    let variants = ["ros2", "link"];
    let mut samples: [Vec<u64>; 2] = [Vec::new(), Vec::new()];
    for round in 0..rounds as usize {
        for k in 0..2 {
            let i = (round + k) % 2;
            let what = format!("ros2-twist: {}", variants[i]);
            match retried(&what, || once(variants[i], per_round, gap)) {
                Ok(mut s) => samples[i].append(&mut s),
                Err(e) => {
                    eprintln!("ros2-twist: {}: {e}", variants[i]);
                    return 1;
                }
            }
        }
    }
    let [ros2, link] = samples;
    let n = ros2.len();
    let (r50, r99, rmax) = percentiles(ros2);
    let (l50, l99, lmax) = percentiles(link);
    println!("ros2-twist ROS 2 topic  p50 {r50:8.2}  p99 {r99:8.2}  max {rmax:9.2} µs  n={n}");
    println!("ros2-twist ferroc link  p50 {l50:8.2}  p99 {l99:8.2}  max {lmax:9.2} µs");
    println!(
        "RESULT ros2-twist p50_us={r50:.2} p99_us={r99:.2} max_us={rmax:.2} messages={n} \
         link_p50_us={l50:.2} link_p99_us={l99:.2} link_max_us={lmax:.2} \
         ratio_p50_vs_link={:.2} gap_us={gap_us}",
        r50 / l50
    );
    0
}
