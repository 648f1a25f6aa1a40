//! A hostile foreign ROS 2 node of bare Zenoh (no code of ours on the wire: its key
//! from the subscription's liveliness token, rmw_zenoh's attachment and the CDR bytes
//! written here by hand), beside `ferroc run models/ros2_crash_course.xml`; the Rust
//! counterpart of `tests/ros2/hostile_peer.py`, fast enough for the 100,000
//! samples per second (one thread, `put`s batched by Zenoh).
//!
//! It listens on a loopback port (the run connects to it; multicast off) and subscribes
//! to `/cmd_vel`. Once the robot moves and the node's `/enable` subscription is
//! announced, it floods `/enable` (std_msgs/msg/Bool) with [`ROUNDS`] rounds of eight
//! samples, as fast as it can put them (what the link cannot carry is dropped at the
//! sender, as by rmw_zenoh's keep-last publishers; the run receives what it can): a
//! CDR header that is not `00 01`, no attachment, a short and a long attachment, a bool
//! of 2..=255, the header alone, a `false` under another type hash (must not reach the
//! robot) and a good `true`. Then it publishes a good `false` every 100 ms until the
//! commands stay zero. Its report has the shape of the Python peer's (what was sent of
//! each kind, the /cmd_vel samples with their phase: before, flood, after, disabled).

use serde_json::json;
use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};
use zenoh::qos::CongestionControl;
use zenoh::{Session, Wait};

/// Rounds of the flood: 7 bad samples each, 140,000 in all (the 100,000 and more).
pub const ROUNDS: u64 = 20_000;

const KINDS: [&str; 8] = [
    "bad_header",
    "no_attachment",
    "short_attachment",
    "long_attachment",
    "bad_bool",
    "truncated",
    "other_hash",
    "valid_true",
];
const PHASES: [&str; 4] = ["before", "flood", "after", "disabled"];

/// The /cmd_vel samples received: the phase (index of [`PHASES`]) and the six values.
type Seen = Arc<Mutex<Vec<(u8, Vec<f64>)>>>;

/// A session listening on `listen` (e.g. `tcp/127.0.0.1:PORT`), peer mode, no multicast.
pub fn open(listen: &str) -> Session {
    let mut config = zenoh::Config::default();
    let set = |c: &mut zenoh::Config, k: &str, v: &str| c.insert_json5(k, v).unwrap();
    set(&mut config, "mode", "\"peer\"");
    set(
        &mut config,
        "listen/endpoints",
        &json!([listen]).to_string(),
    );
    set(&mut config, "connect/endpoints", "[]");
    set(&mut config, "scouting/multicast/enabled", "false");
    zenoh::open(config).wait().unwrap()
}

/// rmw_zenoh's attachment (attachment_helpers.cpp): sequence number and source time,
/// each i64 little endian, the GID's length 16 and the GID.
fn attachment(sequence: i64) -> Vec<u8> {
    let now = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .unwrap()
        .as_nanos() as i64;
    let mut bytes = sequence.to_le_bytes().to_vec();
    bytes.extend(now.to_le_bytes());
    bytes.push(16);
    bytes.extend(0..16u8);
    bytes
}

/// A Bool sample: the CDR header of little-endian XCDR1, then the byte.
fn bool_cdr(value: u8) -> Vec<u8> {
    vec![0, 1, 0, 0, value]
}

/// A small deterministic generator of the bytes that vary (xorshift).
struct Bytes(u64);

impl Bytes {
    fn next(&mut self) -> u8 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 24) as u8
    }
}

/// The key of `/enable` with the hash the run's subscription announces, once the robot
/// moves; `None` at `deadline`.
fn enable_key(session: &Session, moved: &dyn Fn() -> bool, deadline: Instant) -> Option<String> {
    while Instant::now() < deadline {
        let replies = (session.liveliness().get("@ros2_lv/0/**"))
            .timeout(Duration::from_secs(1))
            .wait()
            .unwrap();
        let mut key = None;
        while let Ok(reply) = replies.recv() {
            let Ok(sample) = reply.result() else { continue };
            let token = sample.key_expr().as_str();
            // …/MS/<enclave>/<namespace>/<node>/%enable/<type>/<hash>/<qos>
            let chunks: Vec<&str> = token.split('/').collect();
            if chunks.get(5) == Some(&"MS") && chunks.get(9) == Some(&"%enable") {
                key = Some(format!("0/enable/{}/{}", chunks[10], chunks[11]));
            }
        }
        if let (Some(key), true) = (key, moved()) {
            return Some(key);
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    None
}

/// Runs the node as the module documentation says until done or `seconds` passed: its
/// report (`sent`, `flood_seconds`, `rate`, `samples`).
pub fn run(session: &Session, seconds: u64) -> serde_json::Value {
    let deadline = Instant::now() + Duration::from_secs(seconds);
    let phase = Arc::new(AtomicU8::new(0));
    let samples: Seen = Arc::default();
    let (p, s) = (Arc::clone(&phase), Arc::clone(&samples));
    let _cmd_vel = (session.declare_subscriber("0/cmd_vel/**"))
        .callback(move |sample| {
            let bytes = sample.payload().to_bytes();
            // Twist: the header, then linear and angular, six f64 little endian.
            let values: Vec<f64> = (bytes.get(4..52).unwrap_or_default().chunks(8))
                .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
                .collect();
            if values.len() == 6 {
                let phase = p.load(Ordering::Relaxed);
                s.lock().unwrap().push((phase, values));
            }
        })
        .wait()
        .unwrap();
    let moving = |v: &Vec<f64>| v.iter().any(|x| *x != 0.0);
    let moved = || samples.lock().unwrap().iter().any(|(_, v)| moving(v));
    let key = enable_key(session, &moved, deadline).expect("no /enable subscription, or no motion");
    // As rmw_zenoh's publishers of a keep-last topic (rmw_publisher_data.cpp): what the
    // link cannot take is dropped at the sender, so the flood goes at the flooder's pace.
    let drop = CongestionControl::Drop;
    let publisher = (session.declare_publisher(key.clone()))
        .congestion_control(drop)
        .wait()
        .unwrap();
    let (prefix, _) = key.rsplit_once('/').unwrap();
    let stray = (session.declare_publisher(format!("{prefix}/RIHS01_{}", "5a".repeat(32))))
        .congestion_control(drop)
        .wait()
        .unwrap();

    phase.store(1, Ordering::Relaxed);
    let started = Instant::now();
    let mut bytes = Bytes(29);
    let mut sequence = 0;
    let mut next = || {
        sequence += 1;
        attachment(sequence)
    };
    for _ in 0..ROUNDS {
        let header = [bytes.next() | 2, bytes.next(), 0, 0, 1];
        publisher
            .put(header.to_vec())
            .attachment(next())
            .wait()
            .unwrap();
        publisher.put(bool_cdr(1)).wait().unwrap();
        let short: Vec<u8> = (0..bytes.next() % 33).collect();
        publisher.put(bool_cdr(1)).attachment(short).wait().unwrap();
        let long: Vec<u8> = (0..34 + bytes.next() % 100).collect();
        publisher.put(bool_cdr(1)).attachment(long).wait().unwrap();
        let bad_bool = bool_cdr(2 + bytes.next() % 254);
        publisher.put(bad_bool).attachment(next()).wait().unwrap();
        publisher
            .put(vec![0, 1, 0, 0])
            .attachment(next())
            .wait()
            .unwrap();
        stray.put(bool_cdr(0)).attachment(next()).wait().unwrap();
        publisher
            .put(bool_cdr(1))
            .attachment(next())
            .wait()
            .unwrap();
    }
    let flood_seconds = started.elapsed().as_secs_f64();
    phase.store(2, Ordering::Relaxed);
    // The robot moves on after the flood: wait (bounded) for one moving sample, not for
    // a fixed time a loaded machine may not keep.
    let moved_after = || (samples.lock().unwrap().iter()).any(|(p, v)| *p == 2 && moving(v));
    while !moved_after() && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(50));
    }

    // The part still reads its input: a good `false` stops the robot.
    let first_false = Instant::now();
    while Instant::now() < deadline {
        // Ten samples since, the last five stopped: how long the part takes to apply the
        // `false` is up to the machine; the test checks what came.
        let stopped = {
            let seen = samples.lock().unwrap();
            let disabled: Vec<_> = seen.iter().filter(|(p, _)| *p == 3).collect();
            disabled.len() >= 10
                && !disabled[disabled.len() - 5..]
                    .iter()
                    .any(|(_, v)| moving(v))
        };
        if stopped {
            break;
        }
        publisher
            .put(bool_cdr(0))
            .attachment(next())
            .wait()
            .unwrap();
        if first_false.elapsed() > Duration::from_millis(500) {
            phase.store(3, Ordering::Relaxed);
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    let sent: serde_json::Map<String, serde_json::Value> = (KINDS.iter())
        .map(|k| (k.to_string(), json!(ROUNDS)))
        .collect();
    let samples: Vec<serde_json::Value> = (samples.lock().unwrap().iter())
        .map(|(p, v)| json!({ "phase": PHASES[*p as usize], "linear": v[..3], "angular": v[3..] }))
        .collect();
    let total = ROUNDS * KINDS.len() as u64;
    json!({
        "sent": sent,
        "flood_seconds": flood_seconds,
        "rate": total as f64 / flood_seconds,
        "samples": samples,
    })
}
