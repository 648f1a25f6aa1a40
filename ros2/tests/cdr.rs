//! CDR (XCDR1, little endian) bytes, errors, and hostile input.
//!
//! Expected bytes follow OMG CDR as ROS 2 uses it (encapsulation `00 01 00 00`, each
//! primitive aligned to its size counted from after the header, strings as a u32 length
//! counting the NUL, then the bytes and the NUL); tests/rosbags.rs checks the same rules
//! against an independent implementation for every shipped type.
mod common;

use ferroc_ros2::def::TypeName;
use ferroc_ros2::{cdr, Registry, Value};
use proptest::prelude::*;

fn ty(name: &str) -> TypeName {
    TypeName::parse(name).unwrap()
}

fn s(text: &str) -> Value {
    Value::String(text.into())
}

#[test]
fn golden_bytes_of_small_samples() {
    let r = Registry::shipped();
    let string = cdr::encode(
        &r,
        &ty("std_msgs/msg/String"),
        &Value::Struct(vec![s("hi")]),
    )
    .unwrap();
    assert_eq!(string, [0, 1, 0, 0, 3, 0, 0, 0, b'h', b'i', 0]);
    let header = Value::Struct(vec![
        Value::Struct(vec![Value::I32(1), Value::U32(2)]),
        s("map"),
    ]);
    let bytes = cdr::encode(&r, &ty("std_msgs/msg/Header"), &header).unwrap();
    assert_eq!(
        bytes,
        [0, 1, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0, 4, 0, 0, 0, b'm', b'a', b'p', 0]
    );
    // An empty message is rosidl's one placeholder byte.
    let empty = cdr::encode(&r, &ty("std_msgs/msg/Empty"), &Value::Struct(vec![])).unwrap();
    assert_eq!(empty, [0, 1, 0, 0, 0]);
    assert_eq!(
        cdr::decode(&r, &ty("std_msgs/msg/Empty"), &empty).unwrap(),
        Value::Struct(vec![])
    );
}

#[test]
fn alignment_counts_from_after_the_encapsulation_header() {
    let mut r = Registry::new();
    r.add_text(
        "demo_pkg",
        "msg",
        "Pad",
        "uint8 a\nfloat64 b\nuint16[] c\n",
        "Pad.msg",
    )
    .unwrap();
    let v = Value::Struct(vec![
        Value::U8(7),
        Value::F64(1.0),
        Value::Array(vec![Value::U16(9)]),
    ]);
    let bytes = cdr::encode(&r, &ty("demo_pkg/msg/Pad"), &v).unwrap();
    // a at offset 0, 7 bytes of padding, b at offset 8 (not 4: the header does not count),
    // the sequence's u32 length at 16, its element at 20.
    let mut expected = vec![0, 1, 0, 0, 7, 0, 0, 0, 0, 0, 0, 0];
    expected.extend(1.0f64.to_le_bytes());
    expected.extend([1, 0, 0, 0, 9, 0]);
    assert_eq!(bytes, expected);
    assert_eq!(cdr::decode(&r, &ty("demo_pkg/msg/Pad"), &bytes).unwrap(), v);
}

#[test]
fn values_that_do_not_fit_the_type_are_refused_by_the_encoder() {
    let r = Registry::shipped();
    let vector3 = ty("geometry_msgs/msg/Vector3");
    let e = cdr::encode(&r, &vector3, &Value::Struct(vec![Value::F64(1.0)])).unwrap_err();
    assert!(e.message.contains("has 3 fields, the value has 1"), "{e}");
    let e = cdr::encode(
        &r,
        &vector3,
        &Value::Struct(vec![Value::F64(1.0), Value::F32(1.0), Value::F64(1.0)]),
    )
    .unwrap_err();
    assert_eq!(e.to_string(), "at `y`: expected float64, found float32");
    // Imu's covariances are float64[9].
    let mut g = common::Gen::new(5);
    let imu = ty("sensor_msgs/msg/Imu");
    let Value::Struct(mut fields) = common::value_of(&r, &imu, &mut g) else {
        unreachable!()
    };
    fields[2] = Value::Array(vec![Value::F64(0.0); 8]);
    let e = cdr::encode(&r, &imu, &Value::Struct(fields)).unwrap_err();
    assert_eq!(
        e.to_string(),
        "at `orientation_covariance`: the array has 9 elements, the value has 8"
    );
    let e = cdr::encode(
        &r,
        &ty("std_msgs/msg/String"),
        &Value::Struct(vec![s("a\0b")]),
    )
    .unwrap_err();
    assert!(e.message.contains("NUL"), "{e}");
}

/// A LaserScan of 720 ranges, as a lidar sends it.
fn scan(r: &Registry) -> (TypeName, Vec<u8>) {
    let t = ty("sensor_msgs/msg/LaserScan");
    let mut g = common::Gen::new(720);
    let Value::Struct(mut f) = common::value_of(r, &t, &mut g) else {
        unreachable!()
    };
    f[8] = Value::Array((0..720).map(|i| Value::F32(i as f32 * 0.01)).collect());
    let bytes = cdr::encode(r, &t, &Value::Struct(f)).unwrap();
    (t, bytes)
}

#[test]
fn every_truncation_of_a_sample_is_an_error() {
    let r = Registry::shipped();
    let (t, bytes) = scan(&r);
    assert!(cdr::decode(&r, &t, &bytes).is_ok());
    for cut in 0..bytes.len() {
        assert!(
            cdr::decode(&r, &t, &bytes[..cut]).is_err(),
            "cut at {cut} decoded"
        );
    }
    let e = cdr::decode(&r, &t, &bytes[..bytes.len() - 1]).unwrap_err();
    assert_eq!(e.path, "intensities");
    assert!(e.message.starts_with("the sample ends early"), "{e}");
}

#[test]
fn hostile_lengths_and_bytes_are_errors_without_allocation() {
    let r = Registry::shipped();
    let string = ty("std_msgs/msg/String");
    // A string claiming 4 GiB in an 8-byte sample.
    let e = cdr::decode(&r, &string, &[0, 1, 0, 0, 0xff, 0xff, 0xff, 0xff]).unwrap_err();
    assert!(e.message.contains("does not fit"), "{e}");
    let e = cdr::decode(&r, &string, &[0, 1, 0, 0, 2, 0, 0, 0, b'a', b'b']).unwrap_err();
    assert_eq!(
        e.to_string(),
        "at `data`: the string does not end with a NUL byte"
    );
    let e = cdr::decode(&r, &string, &[0, 1, 0, 0, 0, 0, 0, 0]).unwrap_err();
    assert!(e.message.contains("at least 1"), "{e}");
    let e = cdr::decode(&r, &string, &[0, 0, 0, 0, 1, 0, 0, 0, 0]).unwrap_err();
    assert!(e.message.contains("big-endian"), "{e}");
    let e = cdr::decode(&r, &string, &[0, 1]).unwrap_err();
    assert!(e.message.contains("header is missing"), "{e}");
    let e = cdr::decode(&r, &ty("std_msgs/msg/Bool"), &[0, 1, 0, 0, 2]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "at `data`: a bool is 0 or 1, the sample has 2"
    );
    let e = cdr::decode(&r, &string, &[0, 1, 0, 0, 1, 0, 0, 0, 0, 9, 9, 9, 9]).unwrap_err();
    assert!(e.message.contains("4 bytes are left over"), "{e}");
    // A LaserScan whose ranges claim 2^30 floats.
    let (t, mut bytes) = scan(&r);
    let at = bytes.len() - 4 - 720 * 4 - 4; // ranges' length, before the empty intensities
    assert_eq!(bytes[at..at + 4], 720u32.to_le_bytes());
    bytes[at..at + 4].copy_from_slice(&(1u32 << 30).to_le_bytes());
    let e = cdr::decode(&r, &t, &bytes).unwrap_err();
    assert!(
        e.path == "ranges" && e.message.contains("does not fit"),
        "{e}"
    );
    // A bounded sequence over its bound: a service event with two requests.
    let event = ty("std_srvs/srv/Trigger_Event");
    let mut g = common::Gen::new(1);
    let Value::Struct(mut f) = common::value_of(&r, &event, &mut g) else {
        unreachable!()
    };
    f[1] = Value::Array(vec![Value::Struct(vec![]), Value::Struct(vec![])]);
    let e = cdr::encode(&r, &event, &Value::Struct(f.clone())).unwrap_err();
    assert!(e.message.contains("at most 1"), "{e}");
}

fn shipped_types(r: &Registry) -> Vec<TypeName> {
    r.messages().map(|m| m.name.clone()).collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..600), pick in any::<usize>()) {
        let r = Registry::shipped();
        let types = shipped_types(&r);
        let t = &types[pick % types.len()];
        let mut sample = vec![0, 1, 0, 0];
        sample.extend(bytes);
        let _ = cdr::decode(&r, t, &sample);
    }

    #[test]
    fn every_value_round_trips_and_corruption_never_panics(seed in any::<u64>(), pick in any::<usize>(), flip in any::<(usize, u8)>()) {
        let r = Registry::shipped();
        let types = shipped_types(&r);
        let t = &types[pick % types.len()];
        let value = common::value_of(&r, t, &mut common::Gen::new(seed));
        let bytes = cdr::encode(&r, t, &value).unwrap();
        prop_assert_eq!(&cdr::decode(&r, t, &bytes).unwrap(), &value);
        let mut bad = bytes.clone();
        let at = 4 + flip.0 % (bad.len() - 4);
        bad[at] ^= flip.1 | 1;
        let _ = cdr::decode(&r, t, &bad);
        let _ = cdr::decode(&r, t, &bytes[..at]);
    }
}
