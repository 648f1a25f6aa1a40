//! The serde codec of a port's own value (`serde_cdr`) against the dynamic one (`cdr`):
//! the same bytes for every shipped type's zero value and for generated values, the
//! same values read back, library-like Rust types (Twist, LaserScan, Odometry with
//! ferroc's `Timestamp`) exact through CDR including non-finite floats, one field of a
//! message, wrappers, and hostile samples as errors, never panics.
mod common;

use common::typed::{any_of, Any, TypedMessage};
use ferroc_ros2::def::{Primitive, TypeName};
use ferroc_ros2::serde_cdr::{self, Shape};
use ferroc_ros2::{cdr, json, Registry, Value};
use proptest::prelude::*;
use serde::{Deserialize, Serialize};

fn ty(name: &str) -> TypeName {
    TypeName::parse(name).unwrap()
}

fn check_value(reg: &Registry, name: &TypeName, value: &Value) {
    let m = reg.message(name).unwrap();
    let shape = Shape::new(reg, name, None).unwrap();
    let dynamic = cdr::encode(reg, name, value).unwrap();
    let typed = TypedMessage { reg, m, value };
    let ours = serde_cdr::encode(&shape, &typed).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(ours, dynamic, "{name}: the serde codec writes other bytes");
    if m.fields.is_empty() {
        return;
    }
    let back: Any = serde_cdr::from_cdr(&shape, &dynamic).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_eq!(back, any_of(value), "{name}: read back");
}

#[test]
fn every_shipped_type_s_zero_value_is_the_same_bytes_both_ways() {
    let reg = Registry::shipped();
    let mut n = 0;
    for m in reg.messages() {
        let zero = json::zero(&reg, &m.name).unwrap();
        check_value(&reg, &m.name, &zero);
        n += 1;
    }
    assert!(n > 50, "{n} types");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn generated_values_of_every_type_are_the_same_bytes_both_ways(seed in any::<u64>(), pick in any::<usize>()) {
        let reg = Registry::shipped();
        let types: Vec<TypeName> = reg.messages().map(|m| m.name.clone()).collect();
        let t = &types[pick % types.len()];
        let value = common::value_of(&reg, t, &mut common::Gen::new(seed));
        check_value(&reg, t, &value);
    }

    #[test]
    fn arbitrary_bytes_into_the_serde_decoder_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..800), header in any::<bool>()) {
        let reg = Registry::shipped();
        let shape = Shape::new(&reg, &ty("sensor_msgs/msg/LaserScan"), None).unwrap();
        let mut sample = if header { vec![0, 1, 0, 0] } else { Vec::new() };
        sample.extend(bytes);
        let _ = serde_cdr::from_cdr::<LaserScan>(&shape, &sample);
        let odom = Shape::new(&reg, &ty("nav_msgs/msg/Odometry"), None).unwrap();
        let _ = serde_cdr::from_cdr::<Odometry>(&odom, &sample);
    }
}

// Library-like types, as a team's library (or ferroc_std) declares them.

#[derive(Serialize, Deserialize, Debug, PartialEq, Clone, Copy, Default)]
struct Timestamp {
    nanos: i64,
}

#[derive(Serialize, Deserialize, Debug, PartialEq, Clone, Default)]
struct Header {
    stamp: Timestamp,
    frame_id: String,
}

#[derive(Serialize, Deserialize, Debug, PartialEq, Clone, Default)]
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

#[derive(Serialize, Deserialize, Debug, PartialEq, Clone, Copy, Default)]
struct Vector3 {
    x: f64,
    y: f64,
    z: f64,
}

#[derive(Serialize, Deserialize, Debug, PartialEq, Clone, Copy, Default)]
struct Twist {
    linear: Vector3,
    angular: Vector3,
}

#[derive(Serialize, Deserialize, Debug, PartialEq, Clone, Copy, Default)]
struct Quaternion {
    x: f64,
    y: f64,
    z: f64,
    w: f64,
}

#[derive(Serialize, Deserialize, Debug, PartialEq, Clone, Copy, Default)]
struct Pose {
    position: Vector3,
    orientation: Quaternion,
}

// serde has no arrays longer than 32: a Vec of the array's length is written without
// a length, as the fixed array `float64[36]` is.
#[derive(Serialize, Deserialize, Debug, PartialEq, Clone)]
struct PoseWithCovariance {
    pose: Pose,
    covariance: Vec<f64>,
}

#[derive(Serialize, Deserialize, Debug, PartialEq, Clone)]
struct TwistWithCovariance {
    twist: Twist,
    covariance: Vec<f64>,
}

#[derive(Serialize, Deserialize, Debug, PartialEq, Clone)]
struct Odometry {
    header: Header,
    child_frame_id: String,
    pose: PoseWithCovariance,
    twist: TwistWithCovariance,
}

fn scan() -> LaserScan {
    LaserScan {
        header: Header {
            stamp: Timestamp {
                nanos: 1_700_000_000_123_456_789,
            },
            frame_id: "laser".into(),
        },
        angle_min: -1.5,
        angle_max: 1.5,
        angle_increment: 0.25,
        range_max: 30.0,
        ranges: vec![1.0, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, 0.5],
        intensities: vec![7.0; 5],
        ..LaserScan::default()
    }
}

fn dynamic_scan() -> Value {
    let f = Value::F32;
    Value::Struct(vec![
        Value::Struct(vec![
            Value::Struct(vec![Value::I32(1_700_000_000), Value::U32(123_456_789)]),
            Value::String("laser".into()),
        ]),
        f(-1.5),
        f(1.5),
        f(0.25),
        f(0.0),
        f(0.0),
        f(0.0),
        f(30.0),
        Value::Array(
            [1.0, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, 0.5]
                .map(Value::F32)
                .to_vec(),
        ),
        Value::Array(vec![Value::F32(7.0); 5]),
    ])
}

#[test]
fn a_laser_scan_with_non_finite_ranges_crosses_exactly() {
    let reg = Registry::shipped();
    let t = ty("sensor_msgs/msg/LaserScan");
    let shape = Shape::new(&reg, &t, None).unwrap();
    let bytes = serde_cdr::encode(&shape, &scan()).unwrap();
    assert_eq!(bytes, cdr::encode(&reg, &t, &dynamic_scan()).unwrap());
    let back: LaserScan = serde_cdr::from_cdr(&shape, &bytes).unwrap();
    let bits = |s: &LaserScan| s.ranges.iter().map(|r| r.to_bits()).collect::<Vec<_>>();
    assert_eq!(
        bits(&back),
        bits(&scan()),
        "infinities and NaN stay as they were"
    );
    assert_eq!(back.header, scan().header);
    assert_eq!(back.intensities, scan().intensities);
}

#[test]
fn times_before_1970_and_odometry_round_trip() {
    let reg = Registry::shipped();
    let shape = Shape::new(&reg, &ty("nav_msgs/msg/Odometry"), None).unwrap();
    let mut covariance = vec![0.0; 36];
    covariance[0] = 0.01;
    covariance[35] = f64::INFINITY;
    let odom = Odometry {
        header: Header {
            stamp: Timestamp {
                nanos: -1_500_000_000,
            },
            frame_id: "odom".into(),
        },
        child_frame_id: "base_link".into(),
        pose: PoseWithCovariance {
            pose: Pose {
                position: Vector3 {
                    x: 1.0,
                    y: 2.0,
                    z: 0.0,
                },
                orientation: Quaternion {
                    w: 1.0,
                    ..Default::default()
                },
            },
            covariance: covariance.clone(),
        },
        twist: TwistWithCovariance {
            twist: Twist::default(),
            covariance,
        },
    };
    let bytes = serde_cdr::encode(&shape, &odom).unwrap();
    // -1.5 s is sec -2, nanosec 500000000 (rcl's normalisation: nanosec in [0, 1e9)).
    assert_eq!(
        bytes[4..12],
        [(-2i32).to_le_bytes(), 500_000_000u32.to_le_bytes()].concat()
    );
    let back: Odometry = serde_cdr::from_cdr(&shape, &bytes).unwrap();
    assert_eq!(back, odom);
}

#[test]
fn one_field_of_a_message_and_a_wrapper() {
    let reg = Registry::shipped();
    let t = ty("geometry_msgs/msg/Twist");
    let shape = Shape::new(&reg, &t, Some("angular.z")).unwrap();
    let bytes = serde_cdr::encode(&shape, &-0.25f64).unwrap();
    let twist = Twist {
        angular: Vector3 {
            z: -0.25,
            ..Default::default()
        },
        ..Default::default()
    };
    let whole = Shape::new(&reg, &t, None).unwrap();
    assert_eq!(bytes, serde_cdr::encode(&whole, &twist).unwrap());
    assert_eq!(serde_cdr::from_cdr::<f64>(&shape, &bytes).unwrap(), -0.25);
    let scan_ranges = Shape::new(&reg, &ty("sensor_msgs/msg/LaserScan"), Some("ranges")).unwrap();
    let bytes = serde_cdr::encode(&scan_ranges, &vec![2.0f32, f32::INFINITY]).unwrap();
    let back: Vec<f32> = serde_cdr::from_cdr(&scan_ranges, &bytes).unwrap();
    assert_eq!(back, vec![2.0, f32::INFINITY]);
    // A fixed array of the port against a sequence of the message: a length is written.
    let fixed: [f32; 2] = serde_cdr::from_cdr(&scan_ranges, &bytes).unwrap();
    assert_eq!(fixed, [2.0, f32::INFINITY]);
    assert!(serde_cdr::from_cdr::<[f32; 3]>(&scan_ranges, &bytes).is_err());

    let f64ty = ty("std_msgs/msg/Float64");
    let wrapper = Shape::new(&reg, &f64ty, None).unwrap();
    let bytes = serde_cdr::encode(&wrapper, &f64::NEG_INFINITY).unwrap();
    assert_eq!(
        bytes,
        cdr::encode(
            &reg,
            &f64ty,
            &Value::Struct(vec![Value::F64(f64::NEG_INFINITY)])
        )
        .unwrap()
    );
    assert_eq!(
        serde_cdr::from_cdr::<f64>(&wrapper, &bytes).unwrap(),
        f64::NEG_INFINITY
    );
    let string = Shape::new(&reg, &ty("std_msgs/msg/String"), None).unwrap();
    let bytes = serde_cdr::encode(&string, "hello").unwrap();
    assert_eq!(
        serde_cdr::from_cdr::<String>(&string, &bytes).unwrap(),
        "hello"
    );
}

#[test]
fn values_that_do_not_fit_are_errors_naming_the_field() {
    let reg = Registry::shipped();
    let twist = Shape::new(&reg, &ty("geometry_msgs/msg/Twist"), None).unwrap();
    #[derive(Serialize)]
    struct Wrong {
        linear: Vector3,
        angular: f32,
    }
    let e = serde_cdr::encode(
        &twist,
        &Wrong {
            linear: Vector3::default(),
            angular: 1.0,
        },
    )
    .unwrap_err();
    assert_eq!(e.path, "angular", "{e}");
    #[derive(Serialize)]
    struct Renamed {
        speed: Vector3,
        angular: Vector3,
    }
    let e = serde_cdr::encode(
        &twist,
        &Renamed {
            speed: Vector3::default(),
            angular: Vector3::default(),
        },
    )
    .unwrap_err();
    assert!(e.message.contains("`speed`"), "{e}");
    let e = serde_cdr::encode(&twist, &1.0f64).unwrap_err();
    assert!(e.message.contains("float64"), "{e}");
    let i8ty = Shape::new(&reg, &ty("std_msgs/msg/Int8"), None).unwrap();
    assert!(serde_cdr::encode(&i8ty, &300i32).is_err());
    assert!(Shape::new(&reg, &ty("geometry_msgs/msg/Twist"), Some("linear.w")).is_err());
    let string = Shape::new(&reg, &ty("std_msgs/msg/String"), None).unwrap();
    assert!(serde_cdr::encode(&string, "a\0b").is_err());
}

#[test]
fn malformed_and_short_samples_are_errors() {
    let reg = Registry::shipped();
    let t = ty("sensor_msgs/msg/LaserScan");
    let shape = Shape::new(&reg, &t, None).unwrap();
    let bytes = serde_cdr::encode(&shape, &scan()).unwrap();
    for end in 0..bytes.len() - 3 {
        assert!(
            serde_cdr::from_cdr::<LaserScan>(&shape, &bytes[..end]).is_err(),
            "cut at {end}"
        );
    }
    let mut huge = bytes.clone();
    // The ranges' length: after the header, stamp (8), frame_id (4 + 6, padded to 20)
    // and 7 float32 (28).
    let at = 4 + 20 + 28;
    huge[at..at + 4].copy_from_slice(&u32::MAX.to_le_bytes());
    let e = serde_cdr::from_cdr::<LaserScan>(&shape, &huge).unwrap_err();
    assert_eq!(e.path, "ranges", "{e}");
    let mut long = bytes.clone();
    long.extend([0; 8]);
    assert!(serde_cdr::from_cdr::<LaserScan>(&shape, &long).is_err());
    let twist = Shape::new(&reg, &ty("geometry_msgs/msg/Twist"), None).unwrap();
    assert!(
        serde_cdr::from_cdr::<Twist>(&twist, &bytes).is_err(),
        "another type"
    );
    assert!(
        serde_cdr::from_cdr::<Twist>(&twist, &[0, 0, 0, 0]).is_err(),
        "big endian"
    );
    let _ = Primitive::Bool;
}

/// A LaserScan with infinite and NaN ranges, read by rosbags (not ours) as sent, and
/// one rosbags writes, read by us as written.
#[test]
fn rosbags_reads_our_non_finite_ranges_and_we_read_theirs() {
    let Some(python) = ferroc_testkit::python(&["rosbags", "numpy"]) else {
        return;
    };
    let reg = Registry::shipped();
    let shape = Shape::new(&reg, &ty("sensor_msgs/msg/LaserScan"), None).unwrap();
    let ours = serde_cdr::encode(&shape, &scan()).unwrap();
    let hex: String = ours.iter().map(|b| format!("{b:02x}")).collect();
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/rosbags_nonfinite.py");
    let mut child = std::process::Command::new(python)
        .arg(script)
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("python starts");
    let request = serde_json::json!({ "cdr": hex }).to_string();
    std::io::Write::write_all(&mut child.stdin.take().unwrap(), request.as_bytes()).unwrap();
    let out = child.wait_with_output().expect("python ends");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "rosbags_nonfinite.py failed:\n{stderr}"
    );
    let answer: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    assert_eq!(
        answer["ranges"],
        serde_json::json!(["1.0", "inf", "-inf", "nan", "0.5"]),
        "rosbags read our ranges"
    );
    assert_eq!(answer["frame_id"], "laser");
    assert_eq!(
        answer["stamp"],
        serde_json::json!([1_700_000_000, 123_456_789])
    );

    let text = answer["theirs"].as_str().unwrap();
    let theirs: Vec<u8> = (0..text.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&text[i..i + 2], 16).unwrap())
        .collect();
    let scan: LaserScan = serde_cdr::from_cdr(&shape, &theirs).unwrap();
    assert_eq!(scan.ranges[..2], [f32::INFINITY, f32::NEG_INFINITY]);
    assert!(scan.ranges[2].is_nan());
    assert_eq!(scan.ranges[3], 2.5);
    assert_eq!(scan.header.stamp.nanos, 12_000_000_500);
    assert_eq!(scan.header.frame_id, "their_laser");
}
