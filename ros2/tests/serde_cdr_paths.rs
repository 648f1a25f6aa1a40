//! The three ways the serde codec writes a value (`serde_cdr/fast/`): the checked tape,
//! the trusted writer of a type found to mirror its message, and the plan path every
//! other type takes. All three write the same bytes for every shipped type's generated
//! values; reading along the tape gives what the plan path reads; a type that does not
//! mirror its message takes the plan path (the silent case), and a type that stops
//! visiting what its checked sample visited is checked again, never written wrong.
mod common;

use common::typed::TypedMessage;
use ferroc_ros2::def::{Arity, BaseType, Message, TypeName};
use ferroc_ros2::serde_cdr::{self, Shape};
use ferroc_ros2::{cdr, Registry};
use proptest::prelude::*;
use serde::{Deserialize, Serialize};

fn ty(name: &str) -> TypeName {
    TypeName::parse(name).unwrap()
}

/// Whether the tape takes every `TypedMessage` of `m`: no wstring, and no empty message
/// (serialized as a unit struct, which only the plan path writes; one in a sequence is
/// met only where the sequence is not empty).
fn tape_takes(reg: &Registry, m: &Message) -> bool {
    !m.fields.is_empty()
        && m.fields.iter().all(|f| match &f.ty.base {
            BaseType::WString { .. } => false,
            BaseType::Nested(n) => tape_takes(reg, reg.message(n).unwrap()),
            _ => true,
        })
}

/// Whether the trusted writer takes over a `TypedMessage` of `m` after one sample: no
/// sequence or array of messages, no bounded string, and no Time (a `TypedMessage`
/// writes a Time as its two fields, not as ferroc's `Timestamp`).
fn trusted_takes(reg: &Registry, m: &Message) -> bool {
    let is_time = m.name.package == "builtin_interfaces" && m.name.name == "Time";
    !is_time
        && m.fields.iter().all(|f| match (&f.ty.base, f.ty.arity) {
            (BaseType::String { bound: Some(_) }, _) => false,
            (BaseType::Nested(_), a) if a != Arity::Single => false,
            (BaseType::Nested(n), _) => trusted_takes(reg, reg.message(n).unwrap()),
            _ => true,
        })
}

/// Writes two values of the type `t` every way and compares.
fn check_paths(reg: &Registry, t: &TypeName, seeds: [u64; 2]) {
    let m = reg.message(t).unwrap();
    let shape = Shape::new(reg, t, None).unwrap();
    let mut written = Vec::new();
    for (i, seed) in seeds.into_iter().enumerate() {
        let value = common::value_of(reg, t, &mut common::Gen::new(seed));
        let typed = TypedMessage {
            reg,
            m,
            value: &value,
        };
        let dynamic = cdr::encode(reg, t, &value).unwrap();
        let mut planned = Vec::new();
        serde_cdr::to_cdr_planned(&shape, &typed, &mut planned).unwrap();
        assert_eq!(planned, dynamic, "{t}: the plan path");
        let mut fast = Vec::new();
        let taken = serde_cdr::to_cdr_fast(&shape, &typed, &mut fast);
        assert!(taken || !tape_takes(reg, m), "{t}: the tape misses");
        if taken {
            assert_eq!(fast, dynamic, "{t}: the tape");
        }
        // The first sample is checked; after it, the type is trusted where it
        // qualifies, or known to need the plan path.
        let path = serde_cdr::write_path::<TypedMessage>(&shape);
        let want = match (i, tape_takes(reg, m), trusted_takes(reg, m)) {
            (0, ..) => "tape",
            (_, false, _) if path != "trusted" => path,
            (_, true, true) => "trusted",
            _ => "tape",
        };
        assert_eq!(path, want, "{t}: sample {i}");
        serde_cdr::to_cdr(&shape, &typed, &mut written).unwrap();
        assert_eq!(written, dynamic, "{t}: sample {i} by {path}");
    }
}

#[test]
fn every_shipped_type_is_written_alike_by_every_path() {
    let reg = Registry::shipped();
    let (mut trusted, mut all) = (0, 0);
    for m in reg.messages() {
        check_paths(&reg, &m.name, [1, 2]);
        all += 1;
        trusted += usize::from(tape_takes(&reg, m) && trusted_takes(&reg, m));
    }
    // Most shipped types are on the fast paths (the check above says which).
    assert!(trusted > 30 && all > 50, "{trusted} of {all}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn generated_values_are_written_alike_by_every_path(seed in any::<u64>(), pick in any::<usize>()) {
        let reg = Registry::shipped();
        let types: Vec<TypeName> = reg.messages().map(|m| m.name.clone()).collect();
        check_paths(&reg, &types[pick % types.len()], [seed, seed ^ 0x5eed]);
    }
}

// Library-like types that mirror their messages.

#[derive(Serialize, Deserialize, Debug, PartialEq, Clone, Default)]
struct Timestamp {
    nanos: i64,
}

#[derive(Serialize, Deserialize, Debug, PartialEq, Clone, Default)]
struct Header {
    stamp: Timestamp,
    frame_id: String,
}

#[derive(Serialize, Deserialize, Debug, PartialEq, Clone, Default)]
struct JointState {
    header: Header,
    name: Vec<String>,
    position: Vec<f64>,
    velocity: Vec<f64>,
    effort: Vec<f64>,
}

fn joints(n: usize, stamp: i64) -> JointState {
    JointState {
        header: Header {
            stamp: Timestamp { nanos: stamp },
            frame_id: "base".repeat(n),
        },
        name: (0..n).map(|i| format!("joint_{i}")).collect(),
        position: (0..n).map(|i| i as f64 * 0.25).collect(),
        velocity: vec![f64::NAN; n.min(1)],
        effort: Vec::new(),
    }
}

#[test]
fn a_mirroring_type_is_trusted_after_one_sample_and_read_along_the_tape() {
    let reg = Registry::shipped();
    let shape = Shape::new(&reg, &ty("sensor_msgs/msg/JointState"), None).unwrap();
    let mut buf = Vec::new();
    // Times before 1970 too (a negative `nanos` floors to the second before).
    for (n, stamp) in [
        (0, 0),
        (3, -1),
        (1, 1_700_000_000_999_999_999),
        (7, -2_500_000_001),
    ] {
        let value = joints(n, stamp);
        serde_cdr::to_cdr(&shape, &value, &mut buf).unwrap();
        assert_eq!(serde_cdr::write_path::<JointState>(&shape), "trusted");
        let mut planned = Vec::new();
        serde_cdr::to_cdr_planned(&shape, &value, &mut planned).unwrap();
        assert_eq!(buf, planned, "{n} joints");
        let fast: JointState = serde_cdr::from_cdr_fast(&shape, &buf).unwrap();
        let slow: JointState = serde_cdr::from_cdr_planned(&shape, &buf).unwrap();
        assert_eq!(
            format!("{fast:?}"),
            format!("{slow:?}"),
            "{n} joints (NaN as text)"
        );
        assert_eq!(fast.position, value.position);
    }
}

/// `from_cdr` as the plan path reads it: the value's text (NaN compared as text) or
/// the error.
fn read_as_planned(shape: &Shape<'_>, bytes: &[u8]) -> (String, String) {
    let ours = serde_cdr::from_cdr::<JointState>(shape, bytes);
    let planned = serde_cdr::from_cdr_planned::<JointState>(shape, bytes);
    let text = |r: Result<JointState, ferroc_ros2::cdr::CdrError>| match r {
        Ok(v) => format!("{v:?}"),
        Err(e) => e.to_string(),
    };
    (text(ours), text(planned))
}

/// After one sample read along the tape, a mirroring type is read by the trusted
/// reader, which reads what the plan path reads; every cut and every flipped byte of
/// a sample is refused or read as the plan path reads it, and a good sample after
/// them is read (trusted again).
#[test]
fn a_mirroring_type_is_read_trusted_and_bad_samples_are_refused_as_before() {
    let reg = Registry::shipped();
    let shape = Shape::new(&reg, &ty("sensor_msgs/msg/JointState"), None).unwrap();
    let good = serde_cdr::encode(&shape, &joints(2, 5)).unwrap();
    assert_eq!(serde_cdr::read_path::<JointState>(&shape), "tape");
    serde_cdr::from_cdr::<JointState>(&shape, &good).unwrap();
    assert_eq!(serde_cdr::read_path::<JointState>(&shape), "trusted");
    for (n, stamp) in [(0, 0), (3, -1), (7, -2_500_000_001)] {
        let bytes = serde_cdr::encode(&shape, &joints(n, stamp)).unwrap();
        let trusted = serde_cdr::from_cdr_trusted::<JointState>(&shape, &bytes);
        let (ours, planned) = read_as_planned(&shape, &bytes);
        assert_eq!(format!("{:?}", trusted.unwrap()), planned, "{n} joints");
        assert_eq!(ours, planned);
        let mut bad = Vec::new();
        for cut in 0..bytes.len() {
            bad.push(bytes[..cut].to_vec());
        }
        for at in 4..bytes.len() {
            for flip in [0x01, 0x80, 0xff] {
                let mut b = bytes.clone();
                b[at] ^= flip;
                bad.push(b);
            }
        }
        for b in &bad {
            serde_cdr::from_cdr::<JointState>(&shape, &good).unwrap();
            let (ours, planned) = read_as_planned(&shape, b);
            assert_eq!(ours, planned, "{b:?}");
            if let Some(t) = serde_cdr::from_cdr_trusted::<JointState>(&shape, b) {
                assert_eq!(format!("{t:?}"), planned, "{b:?}");
            }
        }
        serde_cdr::from_cdr::<JointState>(&shape, &good).unwrap();
        assert_eq!(serde_cdr::read_path::<JointState>(&shape), "trusted");
    }
}

/// `std_msgs/msg/Float64` as a plain `f64`: a wrapper only the plan path writes.
#[test]
fn a_type_that_does_not_mirror_its_message_takes_the_plan_path() {
    let reg = Registry::shipped();
    let shape = Shape::new(&reg, &ty("std_msgs/msg/Float64"), None).unwrap();
    let mut fast = Vec::new();
    assert!(!serde_cdr::to_cdr_fast(&shape, &2.5f64, &mut fast));
    let bytes = serde_cdr::encode(&shape, &2.5f64).unwrap();
    assert_eq!(serde_cdr::write_path::<f64>(&shape), "plan");
    let mut planned = Vec::new();
    serde_cdr::to_cdr_planned(&shape, &2.5f64, &mut planned).unwrap();
    assert_eq!(bytes, planned);
    assert_eq!(serde_cdr::from_cdr::<f64>(&shape, &bytes).unwrap(), 2.5);
    assert!(serde_cdr::from_cdr_fast::<f64>(&shape, &bytes).is_none());
    assert!(serde_cdr::from_cdr_trusted::<f64>(&shape, &bytes).is_none());
    assert_eq!(serde_cdr::read_path::<f64>(&shape), "plan");

    // A struct of the message's own shape takes the fast paths (the other side).
    #[derive(Serialize, Deserialize, PartialEq, Debug)]
    struct Float64 {
        data: f64,
    }
    let value = Float64 { data: 2.5 };
    assert_eq!(serde_cdr::encode(&shape, &value).unwrap(), bytes);
    assert_eq!(serde_cdr::write_path::<Float64>(&shape), "trusted");
    assert_eq!(
        serde_cdr::from_cdr_fast::<Float64>(&shape, &bytes),
        Some(value)
    );
    serde_cdr::from_cdr::<Float64>(&shape, &bytes).unwrap();
    assert_eq!(serde_cdr::read_path::<Float64>(&shape), "trusted");
}

/// Skips `effort` when empty: a `JointState` only while it has efforts.
#[derive(Serialize, Default)]
struct Skipping {
    header: Header,
    name: Vec<String>,
    position: Vec<f64>,
    velocity: Vec<f64>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    effort: Vec<f64>,
}

#[test]
fn a_type_that_stops_mirroring_is_checked_again_and_never_written_wrong() {
    let reg = Registry::shipped();
    let shape = Shape::new(&reg, &ty("sensor_msgs/msg/JointState"), None).unwrap();
    let full = Skipping {
        effort: vec![1.0],
        ..Skipping::default()
    };
    serde_cdr::encode(&shape, &full).unwrap();
    assert_eq!(serde_cdr::write_path::<Skipping>(&shape), "trusted");
    // One field fewer: the trusted writer misses, so does the tape; the plan path says.
    let e = serde_cdr::encode(&shape, &Skipping::default()).unwrap_err();
    assert!(e.message.contains("4 fields"), "{e}");
    assert_eq!(serde_cdr::write_path::<Skipping>(&shape), "tape");
    let mut planned = Vec::new();
    serde_cdr::to_cdr_planned(&shape, &full, &mut planned).unwrap();
    assert_eq!(serde_cdr::encode(&shape, &full).unwrap(), planned);
}

const TICKS: &str = "int64 nanos\n";
const STAMPED: &str = "builtin_interfaces/Time stamp\nfast_test/Ticks ticks\n";

/// `Timestamp` where the message has a Time, and another `Timestamp` where it has a
/// message of one `int64 nanos`: written field by field, so never trusted (the trusted
/// writer would take any `Timestamp` for a Time).
#[test]
fn a_timestamp_that_is_not_a_time_keeps_the_type_on_the_checked_tape() {
    let mut reg = Registry::shipped();
    reg.add_text("fast_test", "msg", "Ticks", TICKS, "Ticks.msg")
        .unwrap();
    reg.add_text("fast_test", "msg", "Stamped", STAMPED, "Stamped.msg")
        .unwrap();
    #[derive(Serialize, Deserialize, Debug, PartialEq)]
    struct Stamped {
        stamp: Timestamp,
        ticks: Timestamp,
    }
    let shape = Shape::new(&reg, &ty("fast_test/msg/Stamped"), None).unwrap();
    let value = Stamped {
        stamp: Timestamp {
            nanos: 1_500_000_000,
        },
        ticks: Timestamp {
            nanos: 1_500_000_000,
        },
    };
    for _ in 0..2 {
        let bytes = serde_cdr::encode(&shape, &value).unwrap();
        assert_eq!(serde_cdr::write_path::<Stamped>(&shape), "tape");
        // sec 1, nanosec 5e8, then the int64 as it is.
        let mut want = vec![0, 1, 0, 0, 1, 0, 0, 0, 0x00, 0x65, 0xcd, 0x1d];
        want.extend_from_slice(&1_500_000_000i64.to_le_bytes());
        assert_eq!(bytes, want);
        let back = serde_cdr::from_cdr_fast::<Stamped>(&shape, &bytes);
        assert_eq!(back.as_ref(), Some(&value));
        assert_eq!(
            serde_cdr::from_cdr::<Stamped>(&shape, &bytes).unwrap(),
            value
        );
        assert_eq!(serde_cdr::read_path::<Stamped>(&shape), "tape");
    }
}
