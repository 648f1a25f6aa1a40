//! The mapping checked against the dynamic CDR codec (`ferroc_ros2::cdr`, which reads
//! by the message definition alone, knowing nothing of these types).

use super::*;
use ferroc_ros2::cdr;
use ferroc_ros2::def::TypeName;
use ferroc_ros2::Registry;
use ferroc_ros2::Value;

fn shape(message: &str) -> Shape<'static> {
    let name = TypeName::parse(message).unwrap();
    Shape::new(Registry::shipped_shared(), &name, None).unwrap()
}

fn meta(nanos: i64, frame_id: &str) -> Ros2Meta<'_> {
    Ros2Meta {
        stamp: Timestamp { nanos },
        frame_id,
    }
}

fn decoded(message: &str, bytes: &[u8]) -> Vec<Value> {
    let name = TypeName::parse(message).unwrap();
    match cdr::decode(Registry::shipped_shared(), &name, bytes).unwrap() {
        Value::Struct(fields) => fields,
        other => panic!("{other:?}"),
    }
}

fn header(nanos_sec: i32, nanosec: u32, frame: &str) -> Value {
    Value::Struct(vec![
        Value::Struct(vec![Value::I32(nanos_sec), Value::U32(nanosec)]),
        Value::String(frame.into()),
    ])
}

/// A 3 × 2 rgb8 image whose rows are padded to 10 bytes, data one byte longer.
fn image() -> Image {
    Image {
        width: 3,
        height: 2,
        encoding: "rgb8".into(),
        step: 10,
        data: (0..21).collect::<Vec<u8>>().into(),
    }
}

#[test]
fn an_image_is_written_as_sensor_msgs_image_with_its_header_and_read_back() {
    let s = shape("sensor_msgs/msg/Image");
    let mut bytes = Vec::new();
    let img = image();
    img.to_cdr(&s, &meta(5_000_000_007, "camera"), &mut bytes)
        .unwrap();
    let fields = decoded("sensor_msgs/msg/Image", &bytes);
    let rows: Vec<u8> = (0..20).collect();
    assert_eq!(
        fields,
        vec![
            header(5, 7, "camera"),
            Value::U32(2),
            Value::U32(3),
            Value::String("rgb8".into()),
            Value::U8(0),
            Value::U32(10),
            Value::Bytes(rows.clone()),
        ],
        "the data is cut to step × height"
    );
    let back = Image::from_cdr(&s, &bytes).unwrap();
    assert_eq!(back.data[..], rows[..]);
    assert_eq!((back.width, back.height, back.step), (3, 2, 10));
    assert_eq!(back.encoding, "rgb8");
}

#[test]
fn an_image_the_type_cannot_represent_is_refused_in_words() {
    let s = shape("sensor_msgs/msg/Image");
    let name = TypeName::parse("sensor_msgs/msg/Image").unwrap();
    let sample = |encoding: &str, big: u8, step: u32, data: Vec<u8>| {
        let v = Value::Struct(vec![
            header(0, 0, ""),
            Value::U32(2),
            Value::U32(2),
            Value::String(encoding.into()),
            Value::U8(big),
            Value::U32(step),
            Value::Bytes(data),
        ]);
        cdr::encode(Registry::shipped_shared(), &name, &v).unwrap()
    };
    let err = Image::from_cdr(&s, &sample("mono16", 1, 4, vec![0; 8])).unwrap_err();
    assert!(err.contains("big-endian `mono16`"), "{err}");
    let err = Image::from_cdr(&s, &sample("mono8", 0, 2, vec![0; 3])).unwrap_err();
    assert!(
        err.contains("need 4 bytes") && err.contains("there are 3"),
        "{err}"
    );
    // Silent: big endian says nothing about one-byte channels; longer data is fine.
    assert!(Image::from_cdr(&s, &sample("rgb8", 1, 6, vec![0; 12])).is_ok());
    assert!(Image::from_cdr(&s, &sample("mono8", 0, 2, vec![0; 5])).is_ok());
    // Writing checks too: an image whose data is shorter than its rows is not sent.
    let mut short = image();
    short.data = vec![0; 19].into();
    let err = short.to_cdr(&s, &meta(0, ""), &mut Vec::new()).unwrap_err();
    assert!(err.contains("need 20 bytes"), "{err}");
    // And another message than its own is refused by the codec (`whole`), not here.
}

#[test]
fn a_point_cloud_is_one_row_of_sensor_msgs_point_cloud2_and_reads_back() {
    let s = shape("sensor_msgs/msg/PointCloud2");
    let cloud = PointCloud::xyz(&[[1.0, 2.0, 3.0], [4.0, 5.0, f32::NAN]]);
    let mut bytes = Vec::new();
    cloud.to_cdr(&s, &meta(-1, ""), &mut bytes).unwrap();
    let fields = decoded("sensor_msgs/msg/PointCloud2", &bytes);
    let field = |name: &str, offset| {
        Value::Struct(vec![
            Value::String(name.into()),
            Value::U32(offset),
            Value::U8(7),
            Value::U32(1),
        ])
    };
    assert_eq!(fields[0], header(-1, 999_999_999, ""), "before 1970");
    assert_eq!(&fields[1..3], &[Value::U32(1), Value::U32(2)]);
    assert_eq!(
        fields[3],
        Value::Array(vec![field("x", 0), field("y", 4), field("z", 8)])
    );
    assert_eq!(
        &fields[4..7],
        &[Value::Bool(false), Value::U32(12), Value::U32(24)]
    );
    assert_eq!(fields[7], Value::Bytes(cloud.data.to_vec()));
    assert_eq!(fields[8], Value::Bool(false), "is_dense");
    let back = PointCloud::from_cdr(&s, &bytes).unwrap();
    assert_eq!(
        (back.fields.clone(), back.point_step),
        (cloud.fields.clone(), 12)
    );
    assert_eq!(back.data[..], cloud.data[..]);
    assert!(back.f32_at(1, "z").unwrap().is_nan());
}

#[test]
fn a_point_cloud_the_type_cannot_represent_is_refused_in_words() {
    let s = shape("sensor_msgs/msg/PointCloud2");
    let name = TypeName::parse("sensor_msgs/msg/PointCloud2").unwrap();
    let sample = |big: bool, height: u32, row_step: u32, data: usize| {
        let v = Value::Struct(vec![
            header(0, 0, ""),
            Value::U32(height),
            Value::U32(2),
            Value::Array(vec![]),
            Value::Bool(big),
            Value::U32(4),
            Value::U32(row_step),
            Value::Bytes(vec![0; data]),
            Value::Bool(true),
        ]);
        cdr::encode(Registry::shipped_shared(), &name, &v).unwrap()
    };
    let err = PointCloud::from_cdr(&s, &sample(true, 1, 8, 8)).unwrap_err();
    assert!(err.contains("big-endian"), "{err}");
    let err = PointCloud::from_cdr(&s, &sample(false, 2, 12, 24)).unwrap_err();
    assert!(err.contains("padded rows"), "{err}");
    let err = PointCloud::from_cdr(&s, &sample(false, 2, 8, 12)).unwrap_err();
    assert!(err.contains("need 16 bytes"), "{err}");
    // Silent: an organised cloud (2 rows) without padding is 4 points.
    let four = PointCloud::from_cdr(&s, &sample(false, 2, 8, 16)).unwrap();
    assert_eq!(four.len(), 4);
    // Writing: a partial point is not sent.
    let mut partial = PointCloud::xyz(&[[1.0, 2.0, 3.0]]);
    partial.data = vec![0; 13].into();
    let err = partial
        .to_cdr(&s, &meta(0, ""), &mut Vec::new())
        .unwrap_err();
    assert!(err.contains("13 bytes"), "{err}");
}

/// The value table routes a mapped type's ROS 2 ends through the mapping: the frame
/// given reaches the header, another message or one field of it is refused, and a
/// sample is read into the port. Registered without the mapping (serde only), the same
/// type cannot be written as the message at all.
#[test]
fn the_value_table_writes_and_reads_a_mapped_type_through_its_mapping() {
    use ferroc_runtime::module::{DebugText, DynIn, DynOut, ValueTable};
    use ferroc_runtime::port::ConnectOptions;
    let wire = |table: &ValueTable| -> (DynOut, DynIn) {
        let vt = table.get("ferroc_std.Image").unwrap();
        let (out, oh) = vt.output("out");
        let (inp, ih) = vt.input("in", None);
        oh.connect(&ih, ConnectOptions::default()).unwrap();
        (out, inp)
    };
    let mut mapped = ValueTable::default();
    mapped.insert_ros2::<Image, DebugText>();
    let codec = *mapped.get("ferroc_std.Image").unwrap().codec().unwrap();
    let (out, inp) = wire(&mapped);
    out.typed::<Image>().unwrap().publish(image());
    let s = shape("sensor_msgs/msg/Image");
    let mut bytes = Vec::new();
    codec
        .ros2_encode_framed(&inp, &s, "camera", &mut bytes)
        .unwrap();
    let fields = decoded("sensor_msgs/msg/Image", &bytes);
    let Value::Struct(header) = &fields[0] else {
        panic!("{fields:?}")
    };
    assert_eq!(header[1], Value::String("camera".into()), "the frame given");
    // Stamped now: the wall clock here (no lockstep), after 2026-01-01.
    let Value::Struct(stamp) = &header[0] else {
        panic!("{header:?}")
    };
    assert!(
        matches!(stamp[0], Value::I32(sec) if sec > 1_767_225_600),
        "{stamp:?}"
    );
    let err = (codec.ros2_encode(&inp, &shape("sensor_msgs/msg/PointCloud2"), &mut Vec::new()))
        .unwrap_err();
    assert!(err.contains("carried as `sensor_msgs/msg/Image`"), "{err}");
    let name = TypeName::parse("sensor_msgs/msg/Image").unwrap();
    let data = Shape::new(Registry::shipped_shared(), &name, Some("data")).unwrap();
    assert!(codec.ros2_encode(&inp, &data, &mut Vec::new()).is_err());

    // Read back into a port of the type.
    let (back, seen) = wire(&mapped);
    codec.ros2_decode(&back, &s, &bytes).unwrap();
    assert!(seen.changed());
    assert_eq!(seen.typed::<Image>().unwrap().get().encoding, "rgb8");

    // Serde only: the fields are not the message's.
    let mut plain = ValueTable::default();
    plain.insert_serde::<Image, DebugText>();
    let codec = *plain.get("ferroc_std.Image").unwrap().codec().unwrap();
    let (out, inp) = wire(&plain);
    out.typed::<Image>().unwrap().publish(image());
    assert!(codec.ros2_encode(&inp, &s, &mut Vec::new()).is_err());
}

/// A 1080p rgb8 frame (6.2 MB, the B3 size) crosses whole: one block each way, its
/// sample the data plus the fields around it.
#[test]
fn a_full_hd_frame_crosses_as_one_block() {
    let s = shape("sensor_msgs/msg/Image");
    let mut img = Image::new(1920, 1080, "rgb8").unwrap();
    let data = img.data.to_mut();
    for (i, b) in data.iter_mut().enumerate() {
        *b = (i % 251) as u8;
    }
    let mut bytes = Vec::new();
    img.to_cdr(&s, &meta(0, "camera"), &mut bytes).unwrap();
    // The encapsulation header (4 bytes), then, aligned from the body's start: stamp
    // (8), frame (4 + 7 → 19), height, width (20..28), "rgb8" (4 + 5 → 37),
    // is_bigendian (38), step (40..44), the data's length (48), the data.
    assert_eq!(bytes.len(), 4 + 48 + 6_220_800);
    assert_eq!(&bytes[52..], &img.data[..]);
    let back = Image::from_cdr(&s, &bytes).unwrap();
    assert_eq!(back, img);
}
