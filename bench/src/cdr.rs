//! `cdr` — ROS 2's wire encoding against ours (issue 29): encoding and decoding a
//! `sensor_msgs/LaserScan` of 720 ranges (and 720 intensities) and a `nav_msgs/Odometry`
//! as CDR the way a running part does it (`ferroc_ros2::serde_cdr`: straight from the
//! port's serde value, what `Codec::ros2_encode` and `ros2_decode` call; for these types,
//! which mirror their messages, its fast path) against postcard of the same serde value
//! (the codec of links between parts, `ferroc_module::codec`), and, for reference, the
//! same codec made to take its plan path (guided by the message definition: the path of
//! types that do not mirror their message) and the dynamic `Value` codec
//! (`ferroc_ros2::cdr`, what the interop tests use). Variants interleave in rounds; the
//! best round of each is reported (ns per message, lower is better). `--only
//! CASE_OP_CODEC` (`odom_encode_cdr`) times that one alone, for instruction counts.

use ferroc_ros2::def::TypeName;
use ferroc_ros2::serde_cdr::{self, Shape};
use ferroc_ros2::{cdr, Registry, Value};
use serde::{Deserialize, Serialize};
use std::hint::black_box;
use std::time::Instant;

use crate::options::Options;

const DEFAULT_MESSAGES: u64 = 100_000;
const DEFAULT_ROUNDS: u64 = 5;

/// ferroc's `Timestamp` as its serde form has it (`builtin_interfaces/msg/Time` on the
/// wire).
#[derive(Serialize, Deserialize, Clone)]
struct Timestamp {
    nanos: i64,
}

#[derive(Serialize, Deserialize, Clone)]
struct Header {
    stamp: Timestamp,
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
struct Vector3 {
    x: f64,
    y: f64,
    z: f64,
}

#[derive(Serialize, Deserialize, Clone)]
struct Quaternion {
    x: f64,
    y: f64,
    z: f64,
    w: f64,
}

#[derive(Serialize, Deserialize, Clone)]
struct Pose {
    position: Vector3,
    orientation: Quaternion,
}

#[derive(Serialize, Deserialize, Clone)]
struct Twist {
    linear: Vector3,
    angular: Vector3,
}

/// serde has no arrays over 32 elements: `float64[36]` is a `Vec` of 36 (written
/// without a length, as the fixed array is).
#[derive(Serialize, Deserialize, Clone)]
struct PoseWithCovariance {
    pose: Pose,
    covariance: Vec<f64>,
}

#[derive(Serialize, Deserialize, Clone)]
struct TwistWithCovariance {
    twist: Twist,
    covariance: Vec<f64>,
}

#[derive(Serialize, Deserialize, Clone)]
struct Odometry {
    header: Header,
    child_frame_id: String,
    pose: PoseWithCovariance,
    twist: TwistWithCovariance,
}

fn header(frame: &str) -> (Header, Value) {
    let (sec, nanosec) = (1_764_000_000i32, 123_456_789u32);
    let h = Header {
        stamp: Timestamp {
            nanos: i64::from(sec) * 1_000_000_000 + i64::from(nanosec),
        },
        frame_id: frame.into(),
    };
    let v = Value::Struct(vec![
        Value::Struct(vec![Value::I32(sec), Value::U32(nanosec)]),
        Value::String(h.frame_id.clone()),
    ]);
    (h, v)
}

fn scan() -> (LaserScan, Value) {
    let (h, hv) = header("laser");
    // Some ranges are beyond the sensor's reach: +inf, as REP-117 says.
    let ranges: Vec<f32> = (0..720)
        .map(|i| match i % 90 {
            0 => f32::INFINITY,
            _ => 0.5 + (i as f32) * 0.01,
        })
        .collect();
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
    let cov: Vec<f64> = (0..36)
        .map(|k| if k % 7 == 0 { 0.01 } else { 0.0 })
        .collect();
    let v3 = |x, y, z| Vector3 { x, y, z };
    let o = Odometry {
        header: h,
        child_frame_id: "base_link".into(),
        pose: PoseWithCovariance {
            pose: Pose {
                position: v3(1.5, -2.25, 0.0),
                orientation: Quaternion {
                    x: 0.0,
                    y: 0.0,
                    z: 0.382_683,
                    w: 0.923_880,
                },
            },
            covariance: cov.clone(),
        },
        twist: TwistWithCovariance {
            twist: Twist {
                linear: v3(0.4, 0.0, 0.0),
                angular: v3(0.0, 0.0, 0.3),
            },
            covariance: cov,
        },
    };
    let f64s = |v: &[f64]| Value::Struct(v.iter().map(|x| Value::F64(*x)).collect());
    let vec3 = |v: &Vector3| f64s(&[v.x, v.y, v.z]);
    let flat = |c: &[f64]| Value::Array(c.iter().map(|x| Value::F64(*x)).collect());
    let (p, t) = (&o.pose, &o.twist);
    let q = &p.pose.orientation;
    let v = Value::Struct(vec![
        hv,
        Value::String(o.child_frame_id.clone()),
        Value::Struct(vec![
            Value::Struct(vec![vec3(&p.pose.position), f64s(&[q.x, q.y, q.z, q.w])]),
            flat(&p.covariance),
        ]),
        Value::Struct(vec![
            Value::Struct(vec![vec3(&t.twist.linear), vec3(&t.twist.angular)]),
            flat(&t.covariance),
        ]),
    ]);
    (o, v)
}

/// Mean ns per call of `f` over `n` calls (one round; rounds interleaved by the caller).
fn time(n: u64, mut f: impl FnMut()) -> f64 {
    let start = Instant::now();
    for _ in 0..n {
        f();
    }
    start.elapsed().as_nanos() as f64 / n as f64
}

/// Runs the benchmark and prints its lines. Returns the process exit code.
pub fn run(args: &[String]) -> u8 {
    let parsed = Options::parse("cdr", args, &["messages", "rounds", "only"], &[]).and_then(|o| {
        let only = o.text("only").map(str::to_string);
        let known = |o: &str| {
            (["scan", "odom"].iter())
                .any(|c| VARIANTS.iter().any(|(op, k)| o == format!("{c}_{op}_{k}")))
        };
        if let Some(o) = only.as_deref().filter(|o| !known(o)) {
            return Err(format!(
                "cdr: `--only {o}`: expected CASE_OP_CODEC, CASE scan or odom, OP encode or \
                 decode, CODEC cdr, postcard, plan or dynamic"
            ));
        }
        Ok((
            o.number("messages", DEFAULT_MESSAGES, 1, 100_000_000)?,
            o.number("rounds", DEFAULT_ROUNDS, 1, 1_000)?,
            only,
        ))
    });
    let (n, rounds, only) = match parsed {
        Ok(v) => v,
        Err(e) => {
            eprintln!("{e}");
            return 2;
        }
    };
    match measure(n, rounds, only.as_deref()) {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("cdr: {e}");
            1
        }
    }
}

/// One message type's codecs, timed ([`VARIANTS`]).
struct Case<'r, T> {
    name: &'static str,
    ty: TypeName,
    shape: Shape<'r>,
    value: T,
    dynamic: Value,
    cdr: Vec<u8>,
    postcard: Vec<u8>,
}

impl<'r, T: Serialize + serde::de::DeserializeOwned> Case<'r, T> {
    fn new(
        reg: &'r Registry,
        name: &'static str,
        ty: &str,
        (value, dynamic): (T, Value),
    ) -> Result<Self, String> {
        let ty = TypeName::parse(ty).ok_or("a type name")?;
        let shape = Shape::new(reg, &ty, None)?;
        let cdr = serde_cdr::encode(&shape, &value).map_err(|e| e.to_string())?;
        let same = cdr::encode(reg, &ty, &dynamic).map_err(|e| e.to_string())?;
        if cdr != same {
            return Err(format!("{name}: the serde and the dynamic CDR differ"));
        }
        let postcard = postcard::to_stdvec(&value).map_err(|e| e.to_string())?;
        let mut fast = Vec::new();
        if !serde_cdr::to_cdr_fast(&shape, &value, &mut fast) || fast != cdr {
            return Err(format!("{name}: the fast path does not write the sample"));
        }
        serde_cdr::to_cdr(&shape, &value, &mut fast).map_err(|e| e.to_string())?;
        if serde_cdr::write_path::<T>(&shape) != "trusted" || fast != cdr {
            return Err(format!("{name}: the trusted writer is not taken"));
        }
        if serde_cdr::from_cdr_fast::<T>(&shape, &cdr).is_none() {
            return Err(format!("{name}: the fast path does not read the sample"));
        }
        serde_cdr::from_cdr::<T>(&shape, &cdr).map_err(|e| e.to_string())?;
        if serde_cdr::read_path::<T>(&shape) != "trusted" {
            return Err(format!("{name}: the trusted reader is not taken"));
        }
        println!("{name}: CDR {} B, postcard {} B", cdr.len(), postcard.len());
        Ok(Case {
            name,
            ty,
            shape,
            value,
            dynamic,
            cdr,
            postcard,
        })
    }

    /// One round: ns per message of each variant ([`VARIANTS`]); with `only`, of that one
    /// alone (the others `NaN`: for instruction counts under callgrind).
    fn round(&self, reg: &Registry, n: u64, only: Option<&str>) -> [f64; 8] {
        let mut buf = Vec::new();
        let mut out = [f64::NAN; 8];
        for (k, (op, codec)) in VARIANTS.iter().enumerate() {
            if only.is_some_and(|o| o != format!("{}_{op}_{codec}", self.name)) {
                continue;
            }
            out[k] = match k {
                0 => time(n, || {
                    serde_cdr::to_cdr(&self.shape, black_box(&self.value), &mut buf)
                        .expect("encodes")
                }),
                1 => time(n, || {
                    buf.clear();
                    buf = postcard::to_extend(black_box(&self.value), std::mem::take(&mut buf))
                        .expect("encodes");
                }),
                2 => time(n, || {
                    serde_cdr::to_cdr_planned(&self.shape, black_box(&self.value), &mut buf)
                        .expect("encodes")
                }),
                3 => time(n, || {
                    drop(black_box(cdr::encode(
                        reg,
                        &self.ty,
                        black_box(&self.dynamic),
                    )))
                }),
                4 => time(n, || {
                    drop(black_box(serde_cdr::from_cdr::<T>(
                        &self.shape,
                        black_box(&self.cdr),
                    )))
                }),
                5 => time(n, || {
                    drop(black_box(postcard::from_bytes::<T>(black_box(
                        &self.postcard,
                    ))))
                }),
                6 => time(n, || {
                    drop(black_box(serde_cdr::from_cdr_planned::<T>(
                        &self.shape,
                        black_box(&self.cdr),
                    )))
                }),
                _ => time(n, || {
                    drop(black_box(cdr::decode(reg, &self.ty, black_box(&self.cdr))))
                }),
            };
        }
        out
    }
}

/// What each round times: (operation, codec). `cdr`: what a running part calls
/// (`serde_cdr::to_cdr`/`from_cdr`, the fast path for these types); `plan`: the same
/// codec made to take its plan path (the fallback for types that do not mirror their
/// message); `dynamic`: the `Value` codec.
const VARIANTS: [(&str, &str); 8] = [
    ("encode", "cdr"),
    ("encode", "postcard"),
    ("encode", "plan"),
    ("encode", "dynamic"),
    ("decode", "cdr"),
    ("decode", "postcard"),
    ("decode", "plan"),
    ("decode", "dynamic"),
];

fn measure(n: u64, rounds: u64, only: Option<&str>) -> Result<(), String> {
    let reg = Registry::shipped();
    let scan = Case::new(&reg, "scan", "sensor_msgs/msg/LaserScan", scan())?;
    let odom = Case::new(&reg, "odom", "nav_msgs/msg/Odometry", odometry())?;
    let mut best = [[f64::MAX; 8]; 2];
    for _ in 0..rounds {
        let t = [scan.round(&reg, n, only), odom.round(&reg, n, only)];
        for (b, t) in best.iter_mut().zip(t) {
            for (b, t) in b.iter_mut().zip(t) {
                *b = b.min(t);
            }
        }
    }
    let mut result = String::from("RESULT cdr");
    for (name, b) in [scan.name, odom.name].into_iter().zip(best) {
        // Not timed (`--only`): NaN, not the starting maximum.
        let b = b.map(|t| if t == f64::MAX { f64::NAN } else { t });
        for (op, b) in [("encode", &b[..4]), ("decode", &b[4..])] {
            let (c, p, plan, d) = (b[0], b[1], b[2], b[3]);
            println!(
                "{name} {op}: CDR from the value {c:.0} ns, postcard {p:.0} ns, ratio {:.2}; \
                 by the plan path {plan:.0} ns (ratio {:.2}); CDR of a dynamic Value {d:.0} ns",
                c / p,
                plan / p
            );
            result.push_str(&format!(
                " {name}_{op}_cdr_ns={c:.0} {name}_{op}_postcard_ns={p:.0} {name}_{op}_ratio={:.2} \
                 {name}_{op}_plan_ns={plan:.0} {name}_{op}_dynamic_ns={d:.0}",
                c / p
            ));
        }
    }
    println!("{result}");
    Ok(())
}
