//! `cdr` — ROS 2's wire encoding against ours (issue 29): encoding and decoding a
//! `sensor_msgs/LaserScan` of 720 ranges (and 720 intensities) and a `nav_msgs/Odometry`
//! as CDR (`ferroc-ros2`: a dynamic `Value` of the parsed definition, as a ROS-typed port
//! would hand it over today) against postcard of the same data as serde structs (the
//! codec of links between parts, `ferroc_module::codec`). Variants interleave in rounds;
//! the best round of each is reported (ns per message, lower is better).

use ferroc_ros2::def::TypeName;
use ferroc_ros2::{cdr, Registry, Value};
use serde::{Deserialize, Serialize};
use std::hint::black_box;
use std::time::Instant;

use crate::options::Options;

const DEFAULT_MESSAGES: u64 = 100_000;
const DEFAULT_ROUNDS: u64 = 5;

#[derive(Serialize, Deserialize, Clone)]
struct Header {
    sec: i32,
    nanosec: u32,
    frame_id: String,
}

#[derive(Serialize, Deserialize, Clone)]
struct LaserScan {
    header: Header,
    angle_min: f32,
    angle_max: f32,
    angle_increment: f32,
    time_increment: f32,
    scan_time: f32,
    range_min: f32,
    range_max: f32,
    ranges: Vec<f32>,
    intensities: Vec<f32>,
}

#[derive(Serialize, Deserialize, Clone)]
struct Odometry {
    header: Header,
    child_frame_id: String,
    position: [f64; 3],
    orientation: [f64; 4],
    pose_covariance: [[f64; 6]; 6],
    linear: [f64; 3],
    angular: [f64; 3],
    twist_covariance: [[f64; 6]; 6],
}

fn header(frame: &str) -> (Header, Value) {
    let h = Header {
        sec: 1_764_000_000,
        nanosec: 123_456_789,
        frame_id: frame.into(),
    };
    let v = Value::Struct(vec![
        Value::Struct(vec![Value::I32(h.sec), Value::U32(h.nanosec)]),
        Value::String(h.frame_id.clone()),
    ]);
    (h, v)
}

fn scan() -> (LaserScan, Value) {
    let (h, hv) = header("laser");
    let ranges: Vec<f32> = (0..720).map(|i| 0.5 + (i as f32) * 0.01).collect();
    let intensities: Vec<f32> = (0..720).map(|i| (i % 100) as f32).collect();
    let floats = |v: &[f32]| Value::Array(v.iter().map(|x| Value::F32(*x)).collect());
    let s = LaserScan {
        header: h,
        angle_min: -std::f32::consts::PI,
        angle_max: std::f32::consts::PI,
        angle_increment: std::f32::consts::TAU / 720.0,
        time_increment: 1e-4,
        scan_time: 0.1,
        range_min: 0.05,
        range_max: 30.0,
        ranges,
        intensities,
    };
    let mut fields = vec![hv];
    fields.extend(
        [
            s.angle_min,
            s.angle_max,
            s.angle_increment,
            s.time_increment,
            s.scan_time,
            s.range_min,
            s.range_max,
        ]
        .map(Value::F32),
    );
    fields.push(floats(&s.ranges));
    fields.push(floats(&s.intensities));
    (s, Value::Struct(fields))
}

fn odometry() -> (Odometry, Value) {
    let (h, hv) = header("odom");
    let cov: [[f64; 6]; 6] =
        std::array::from_fn(|i| std::array::from_fn(|j| if i == j { 0.01 } else { 0.0 }));
    let o = Odometry {
        header: h,
        child_frame_id: "base_link".into(),
        position: [1.5, -2.25, 0.0],
        orientation: [0.0, 0.0, 0.382_683, 0.923_880],
        pose_covariance: cov,
        linear: [0.4, 0.0, 0.0],
        angular: [0.0, 0.0, 0.3],
        twist_covariance: cov,
    };
    let f64s = |v: &[f64]| v.iter().map(|x| Value::F64(*x)).collect::<Vec<_>>();
    let flat =
        |c: &[[f64; 6]; 6]| Value::Array(c.iter().flatten().map(|x| Value::F64(*x)).collect());
    let v = Value::Struct(vec![
        hv,
        Value::String(o.child_frame_id.clone()),
        Value::Struct(vec![
            Value::Struct(vec![
                Value::Struct(f64s(&o.position)),
                Value::Struct(f64s(&o.orientation)),
            ]),
            flat(&o.pose_covariance),
        ]),
        Value::Struct(vec![
            Value::Struct(vec![
                Value::Struct(f64s(&o.linear)),
                Value::Struct(f64s(&o.angular)),
            ]),
            flat(&o.twist_covariance),
        ]),
    ]);
    (o, v)
}

/// Best ns per call of `f` over `rounds` rounds of `n` calls, rounds interleaved by the caller.
fn time(n: u64, mut f: impl FnMut()) -> f64 {
    let start = Instant::now();
    for _ in 0..n {
        f();
    }
    start.elapsed().as_nanos() as f64 / n as f64
}

/// Runs the benchmark and prints its lines. Returns the process exit code.
pub fn run(args: &[String]) -> u8 {
    let parsed = Options::parse("cdr", args, &["messages", "rounds"], &[]).and_then(|o| {
        Ok((
            o.number("messages", DEFAULT_MESSAGES, 1, 100_000_000)?,
            o.number("rounds", DEFAULT_ROUNDS, 1, 1_000)?,
        ))
    });
    let (n, rounds) = match parsed {
        Ok(v) => v,
        Err(e) => {
            eprintln!("{e}");
            return 2;
        }
    };
    match measure(n, rounds) {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("cdr: {e}");
            1
        }
    }
}

fn measure(n: u64, rounds: u64) -> Result<(), String> {
    let registry = Registry::shipped();
    let scan_t = TypeName::parse("sensor_msgs/msg/LaserScan").expect("name");
    let odom_t = TypeName::parse("nav_msgs/msg/Odometry").expect("name");
    let (scan_s, scan_v) = scan();
    let (odom_s, odom_v) = odometry();
    let scan_cdr = cdr::encode(&registry, &scan_t, &scan_v).map_err(|e| e.to_string())?;
    let odom_cdr = cdr::encode(&registry, &odom_t, &odom_v).map_err(|e| e.to_string())?;
    let scan_pc = postcard::to_stdvec(&scan_s).map_err(|e| e.to_string())?;
    let odom_pc = postcard::to_stdvec(&odom_s).map_err(|e| e.to_string())?;
    println!(
        "sizes: LaserScan CDR {} B, postcard {} B; Odometry CDR {} B, postcard {} B",
        scan_cdr.len(),
        scan_pc.len(),
        odom_cdr.len(),
        odom_pc.len()
    );
    // [scan enc cdr, scan enc pc, scan dec cdr, scan dec pc, odom ×4]
    let mut best = [f64::MAX; 8];
    let mut buf = Vec::new();
    for _ in 0..rounds {
        let t = [
            time(n, || {
                drop(black_box(cdr::encode(
                    &registry,
                    &scan_t,
                    black_box(&scan_v),
                )))
            }),
            time(n, || {
                buf.clear();
                buf = postcard::to_extend(black_box(&scan_s), std::mem::take(&mut buf))
                    .expect("encodes");
            }),
            time(n, || {
                drop(black_box(cdr::decode(
                    &registry,
                    &scan_t,
                    black_box(&scan_cdr),
                )))
            }),
            time(n, || {
                drop(black_box(postcard::from_bytes::<LaserScan>(black_box(
                    &scan_pc,
                ))))
            }),
            time(n, || {
                drop(black_box(cdr::encode(
                    &registry,
                    &odom_t,
                    black_box(&odom_v),
                )))
            }),
            time(n, || {
                buf.clear();
                buf = postcard::to_extend(black_box(&odom_s), std::mem::take(&mut buf))
                    .expect("encodes");
            }),
            time(n, || {
                drop(black_box(cdr::decode(
                    &registry,
                    &odom_t,
                    black_box(&odom_cdr),
                )))
            }),
            time(n, || {
                drop(black_box(postcard::from_bytes::<Odometry>(black_box(
                    &odom_pc,
                ))))
            }),
        ];
        for (b, t) in best.iter_mut().zip(t) {
            *b = b.min(t);
        }
    }
    let names = [
        "LaserScan encode",
        "LaserScan decode",
        "Odometry encode",
        "Odometry decode",
    ];
    let mut result = String::from("RESULT cdr");
    for (i, name) in names.iter().enumerate() {
        let (c, p) = (best[2 * i], best[2 * i + 1]);
        println!(
            "{name}: CDR {c:.0} ns, postcard {p:.0} ns, ratio {:.2}",
            c / p
        );
        let key = name
            .to_lowercase()
            .replace(' ', "_")
            .replace("laserscan", "scan")
            .replace("odometry", "odom");
        result.push_str(&format!(
            " {key}_cdr_ns={c:.0} {key}_postcard_ns={p:.0} {key}_ratio={:.2}",
            c / p
        ));
    }
    println!("{result}");
    Ok(())
}
