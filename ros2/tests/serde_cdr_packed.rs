//! Arrays of primitives on the fast paths (`serde_cdr/fast/packed.rs`): room for the
//! whole array is made when it begins and each element is written into it. The bytes
//! are XCDR1's (a hand-worked sample), a `Vec` and a fixed array visited as a tuple are
//! written alike by the trusted writer, the checked tape and the plan path, and a value
//! whose elements are not what the array holds, or not as many as it said, is never
//! written wrong: it misses and the plan path decides.
use ferroc_ros2::def::TypeName;
use ferroc_ros2::serde_cdr::{self, Shape};
use ferroc_ros2::Registry;
use serde::ser::{SerializeSeq, SerializeStruct, SerializeTuple};
use serde::{Deserialize, Serialize, Serializer};

/// Every width of primitive, each as a sequence, a bounded one or a fixed array, with
/// the padding before counts and first elements all different.
const PACKED: &str = "uint8 a\nfloat64[] xs\nint16[3] s\nbool[] flags\nuint8[] raw\n\
                      float32[2] fs\nint64[<=4] ls\n";

fn registry() -> Registry {
    let mut reg = Registry::shipped();
    reg.add_text("packed_test", "msg", "Packed", PACKED, "Packed.msg")
        .unwrap();
    reg
}

fn shape(reg: &Registry) -> Shape<'_> {
    Shape::new(
        reg,
        &TypeName::parse("packed_test/msg/Packed").unwrap(),
        None,
    )
    .unwrap()
}

#[derive(Serialize, Deserialize, Debug, PartialEq, Clone, Default)]
struct Packed {
    a: u8,
    xs: Vec<f64>,
    s: [i16; 3],
    flags: Vec<bool>,
    raw: Vec<u8>,
    fs: [f32; 2],
    ls: Vec<i64>,
}

fn small() -> Packed {
    Packed {
        a: 1,
        xs: vec![2.0],
        s: [1, 2, 3],
        flags: vec![true],
        raw: vec![9, 8],
        fs: [0.5, 1.5],
        ls: vec![7],
    }
}

/// `small()` worked out by hand from XCDR1's rules (offsets after the 4-byte header;
/// each primitive and count aligned to its size, a fixed array without a count).
fn small_bytes() -> Vec<u8> {
    let mut b = vec![0x00, 0x01, 0x00, 0x00];
    b.push(1); // a, offset 0
    b.extend([0; 3]); // to 4
    b.extend(1u32.to_le_bytes()); // xs: count, offset 4
    b.extend(2.0f64.to_le_bytes()); // offset 8, aligned already
    for v in [1i16, 2, 3] {
        b.extend(v.to_le_bytes()); // s: offsets 16, 18, 20
    }
    b.extend([0; 2]); // to 24
    b.extend(1u32.to_le_bytes()); // flags: count
    b.push(1); // offset 28
    b.extend([0; 3]); // to 32
    b.extend(2u32.to_le_bytes()); // raw: count
    b.extend([9, 8]); // offsets 36, 37
    b.extend([0; 2]); // to 40
    b.extend(0.5f32.to_le_bytes()); // fs
    b.extend(1.5f32.to_le_bytes());
    b.extend(1u32.to_le_bytes()); // ls: count, offset 48
    b.extend([0; 4]); // to 56
    b.extend(7i64.to_le_bytes());
    b
}

fn planned<T: Serialize>(shape: &Shape<'_>, value: &T) -> Result<Vec<u8>, String> {
    let mut buf = Vec::new();
    serde_cdr::to_cdr_planned(shape, value, &mut buf).map_err(|e| e.to_string())?;
    Ok(buf)
}

#[test]
fn packed_arrays_are_written_as_xcdr1_says_by_every_path() {
    let reg = registry();
    let shape = shape(&reg);
    assert_eq!(planned(&shape, &small()).unwrap(), small_bytes());
    let mut tape = Vec::new();
    assert!(serde_cdr::to_cdr_fast(&shape, &small(), &mut tape));
    assert_eq!(tape, small_bytes());
    let many = Packed {
        a: 0xff,
        xs: (0..100).map(|i| i as f64 / 3.0).collect(),
        s: [-1, 0, i16::MAX],
        flags: vec![false, true, true],
        raw: (0..=255).collect(),
        fs: [f32::INFINITY, -0.0],
        ls: vec![i64::MIN, -1, 0, i64::MAX],
    };
    let empty = Packed::default();
    let mut buf = Vec::new();
    for value in [small(), many, empty, small()] {
        serde_cdr::to_cdr(&shape, &value, &mut buf).unwrap();
        assert_eq!(serde_cdr::write_path::<Packed>(&shape), "trusted");
        assert_eq!(buf, planned(&shape, &value).unwrap());
        assert_eq!(serde_cdr::from_cdr::<Packed>(&shape, &buf).unwrap(), value);
    }
}

/// `float64[36]` as serde can hold it: a `Vec` (a sequence of 36, written without a
/// count), or an array visited as a tuple (what ferroc's `fixed36` helper does).
#[derive(Serialize)]
struct PoseWithCovariance<C> {
    pose: Pose,
    covariance: C,
}

struct Tuple36([f64; 36]);

impl Serialize for Tuple36 {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut t = s.serialize_tuple(36)?;
        for v in &self.0 {
            t.serialize_element(v)?;
        }
        t.end()
    }
}

fn pose_message_shape(reg: &Registry) -> Shape<'_> {
    let ty = TypeName::parse("geometry_msgs/msg/PoseWithCovariance").unwrap();
    Shape::new(reg, &ty, None).unwrap()
}

#[derive(Serialize)]
struct Point {
    x: f64,
    y: f64,
    z: f64,
}

#[derive(Serialize)]
struct Quaternion {
    x: f64,
    y: f64,
    z: f64,
    w: f64,
}

#[derive(Serialize)]
struct Pose {
    position: Point,
    orientation: Quaternion,
}

fn pose() -> Pose {
    Pose {
        position: Point {
            x: 1.5,
            y: -2.25,
            z: 0.0,
        },
        orientation: Quaternion {
            x: 0.0,
            y: 0.0,
            z: 0.382_683,
            w: 0.923_880,
        },
    }
}

#[test]
fn a_fixed_array_is_written_alike_as_a_vec_and_as_a_tuple() {
    let reg = Registry::shipped();
    let shape = pose_message_shape(&reg);
    let cov: [f64; 36] = std::array::from_fn(|k| if k % 7 == 0 { 0.01 } else { k as f64 });
    let as_vec = PoseWithCovariance {
        pose: pose(),
        covariance: cov.to_vec(),
    };
    let as_tuple = PoseWithCovariance {
        pose: pose(),
        covariance: Tuple36(cov),
    };
    let want = planned(&shape, &as_vec).unwrap();
    assert_eq!(want.len(), 4 + 7 * 8 + 36 * 8);
    assert_eq!(planned(&shape, &as_tuple).unwrap(), want);
    // Trusted after one sample (one type at a time: the last one checked).
    for _ in 0..2 {
        assert_eq!(serde_cdr::encode(&shape, &as_vec).unwrap(), want);
        assert_eq!(serde_cdr::encode(&shape, &as_vec).unwrap(), want);
        let path = serde_cdr::write_path::<PoseWithCovariance<Vec<f64>>>(&shape);
        assert_eq!(path, "trusted");
        assert_eq!(serde_cdr::encode(&shape, &as_tuple).unwrap(), want);
        assert_eq!(serde_cdr::encode(&shape, &as_tuple).unwrap(), want);
        let path = serde_cdr::write_path::<PoseWithCovariance<Tuple36>>(&shape);
        assert_eq!(path, "trusted");
    }
    // 35 or 37 elements: not the array, by any path.
    for n in [35, 37] {
        let wrong = PoseWithCovariance {
            pose: pose(),
            covariance: vec![0.5; n],
        };
        assert!(serde_cdr::encode(&shape, &wrong).is_err(), "{n} elements");
        let mut tape = Vec::new();
        assert!(!serde_cdr::to_cdr_fast(&shape, &wrong, &mut tape));
    }
}

/// A `Packed` that visits, when told, one of its arrays in a way the message does not
/// have: `xs` as `f32`s, or `ls` with a length hint one more or one less than the
/// elements it then visits.
#[derive(Clone)]
struct Wayward {
    value: Packed,
    how: How,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum How {
    Mirroring,
    Narrower,
    SaysMore,
    SaysFewer,
}

impl Serialize for Wayward {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let v = &self.value;
        let mut st = s.serialize_struct("Packed", 7)?;
        st.serialize_field("a", &v.a)?;
        match self.how {
            How::Narrower => {
                let xs: Vec<f32> = v.xs.iter().map(|x| *x as f32).collect();
                st.serialize_field("xs", &xs)?;
            }
            _ => st.serialize_field("xs", &v.xs)?,
        }
        st.serialize_field("s", &v.s)?;
        st.serialize_field("flags", &v.flags)?;
        st.serialize_field("raw", &v.raw)?;
        st.serialize_field("fs", &v.fs)?;
        let said = match self.how {
            How::SaysMore => v.ls.len() + 1,
            How::SaysFewer => v.ls.len().saturating_sub(1),
            _ => v.ls.len(),
        };
        st.serialize_field("ls", &Said(&v.ls, said))?;
        st.end()
    }
}

/// A sequence that says it has `.1` elements and visits those of `.0`.
struct Said<'a>(&'a [i64], usize);

impl Serialize for Said<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut seq = s.serialize_seq(Some(self.1))?;
        for v in self.0 {
            seq.serialize_element(v)?;
        }
        seq.end()
    }
}

#[test]
fn a_packed_array_not_as_its_checked_sample_was_is_never_written_wrong() {
    let reg = registry();
    let mut value = small();
    value.ls = vec![1, 2];
    let trusted = Wayward {
        value: value.clone(),
        how: How::Mirroring,
    };
    for how in [How::Narrower, How::SaysMore, How::SaysFewer] {
        // A shape of its own each time (a type the plan path wrote after a miss takes
        // the plan path from then on).
        let shape = shape(&reg);
        serde_cdr::encode(&shape, &trusted).unwrap();
        assert_eq!(serde_cdr::write_path::<Wayward>(&shape), "trusted");
        let wayward = Wayward {
            value: value.clone(),
            how,
        };
        let mut tape = Vec::new();
        assert!(
            !serde_cdr::to_cdr_fast(&shape, &wayward, &mut tape),
            "{how:?}: the tape takes it"
        );
        // Whatever the plan path makes of it (an error, or the bytes with each `f32`
        // widened), the fast paths agree or stay out of the way.
        let got = serde_cdr::encode(&shape, &wayward).map_err(|e| e.to_string());
        assert_eq!(got, planned(&shape, &wayward), "{how:?}");
        assert_ne!(serde_cdr::write_path::<Wayward>(&shape), "trusted");
    }
}
