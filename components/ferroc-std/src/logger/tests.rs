use super::*;
use crate::recording::ChannelInfo;

#[test]
fn missing_folders_are_accepted_and_created_when_the_recording_opens() {
    let dir = std::env::temp_dir().join(format!("ferroc-logger-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let path = dir.join("agv/trajectory.mcap");
    assert_eq!(check_log_path(&path), Ok(()));
    assert!(!dir.exists(), "checking creates nothing");
    let log = LogFile::open_shared(&path, 1).unwrap();
    // A second opener joins the same recording instead of truncating it.
    let again = LogFile::open_shared(&path, 1).unwrap();
    assert!(std::sync::Arc::ptr_eq(&log, &again));
    drop((log, again));
    let rec = recording::Recording::read(&path).unwrap();
    assert!(rec.finished && rec.damaged.is_none() && rec.messages.is_empty());
    // A file where a folder should be is refused when checked.
    let e = check_log_path(&path.join("x.mcap")).unwrap_err();
    assert!(e.contains("is not a folder"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The cost per message of recording a 100 Hz stream of 4×4 matrices, in the
/// logging container (encoding, JSON mirror, the shared file's lock, chunk writes and
/// the flush once per second of log time). A figure, not an assertion: run
/// `cargo test --release -p ferroc-std logging_cost -- --ignored --nocapture`.
#[test]
#[ignore]
fn logging_cost_of_a_100_hz_matrix_stream() {
    use ferroc_runtime::module::ValueTable;
    use ferroc_runtime::port::ConnectOptions;
    let table = ValueTable::default();
    let vt = table.get("f64[4][4]").expect("registered");
    let dir = std::env::temp_dir().join(format!("ferroc-logcost-{}", std::process::id()));
    for json in [true, false] {
        let (out, oh) = vt.output("out");
        let (input, ih) = vt.input("in/0", None);
        oh.connect(&ih, ConnectOptions::default()).unwrap();
        let info = ChannelInfo {
            topic: "bench/matrix".into(),
            model_type: "f64[4][4]".into(),
            ..ChannelInfo::default()
        };
        let mut ports = vec![Recorded::new(input, *vt.wire().unwrap(), info)];
        let path = dir.join(format!("matrix-{json}.mcap"));
        let log = LogFile::open_shared(&path, 1_000_000_000).unwrap();
        let (mut exact, mut text) = (Vec::new(), Vec::new());
        let n = 30_000u64;
        let mut spent = std::time::Duration::ZERO;
        for k in 0..n {
            let mut m = [[0.0f64; 4]; 4];
            m[k as usize % 4][k as usize % 3] = k as f64 * 0.001;
            m[3][3] = 1.0;
            out.typed::<[[f64; 4]; 4]>().unwrap().publish(m);
            // 100 Hz of log time, so the once-a-second flush happens as it would.
            let now = k * 10_000_000;
            let started = std::time::Instant::now();
            record_at(&log, &mut ports, now, json, &mut exact, &mut text).unwrap();
            spent += started.elapsed();
        }
        drop(log);
        let rec = recording::Recording::read(&path).unwrap();
        assert_eq!(rec.messages.len() as u64, if json { 2 * n } else { n });
        println!(
            "json mirror {json}: {:.2} µs per message ({n} messages, {} bytes)",
            spent.as_secs_f64() * 1e6 / n as f64,
            std::fs::metadata(&path).unwrap().len()
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Declares the ROS 2 node of the tests with `topics`: `(id, publish, module, port,
/// topic, field)`, each an f64 port as `std_msgs/msg/Float64` (`data`) or as one field of
/// `geometry_msgs/msg/Vector3`.
fn declare(topics: &[(u32, bool, &str, &str, &str, &str)]) {
    use ferroc_runtime::link::ros2::{Ros2Node, Ros2Qos, Ros2Topic};
    let topics = (topics.iter())
        .map(|&(id, publish, module, port, topic, field)| Ros2Topic {
            id,
            publish,
            port: (module.into(), port.into()),
            model_type: "f64".into(),
            topic: topic.into(),
            message: if field == "data" {
                "std_msgs/msg/Float64"
            } else {
                "geometry_msgs/msg/Vector3"
            }
            .into(),
            field: Some(field.into()),
            qos: Ros2Qos::default(),
            frame_id: String::new(),
        })
        .collect();
    let node = Ros2Node {
        part: "robot".into(),
        domain: 0,
        namespace: "/".into(),
        name: "robot".into(),
        topics,
        services: vec![],
        clients: vec![],
        interfaces: vec![],
    };
    ferroc_runtime::link::ros2_wire::add_node(&node).unwrap();
}

/// Records `values` of an f64 output at `port` (a log time each) into `path`.
fn record_values(path: &std::path::Path, port: &str, values: &[f64]) {
    record_ports(path, &[port], values);
}

/// Records `values` of f64 outputs at each of `ports` (a log time each) into `path`.
fn record_ports(path: &std::path::Path, ports: &[&str], values: &[f64]) {
    use ferroc_runtime::module::ValueTable;
    use ferroc_runtime::port::ConnectOptions;
    recording::ros2::add_recorded(ports.iter().copied());
    let table = ValueTable::default();
    let vt = table.get("f64").expect("registered");
    let mut outs = Vec::new();
    let mut recorded = Vec::new();
    for port in ports {
        let (out, oh) = vt.output("out");
        let (input, ih) = vt.input("in/0", None);
        oh.connect(&ih, ConnectOptions::default()).unwrap();
        let info = ChannelInfo {
            topic: (*port).into(),
            port: (*port).into(),
            part: "robot".into(),
            model_type: "f64".into(),
            unit: "m".into(),
            ..ChannelInfo::default()
        };
        outs.push(out);
        recorded.push(Recorded::new(input, *vt.wire().unwrap(), info));
    }
    let log = LogFile::open_shared(path, 1).unwrap();
    let (mut exact, mut text) = (Vec::new(), Vec::new());
    for (k, x) in values.iter().enumerate() {
        for out in &outs {
            out.typed::<f64>().unwrap().publish(*x);
        }
        record_at(
            &log,
            &mut recorded,
            k as u64 * 1000,
            true,
            &mut exact,
            &mut text,
        )
        .unwrap();
    }
}

/// The recorded messages of `channel`.
fn messages_of(rec: &recording::Recording, channel: u16) -> Vec<&Vec<u8>> {
    (rec.messages.iter())
        .filter(|m| m.channel == channel)
        .map(|m| &m.data)
        .collect()
}

#[test]
fn a_port_published_as_a_ros2_topic_gets_a_cdr_channel_with_every_value_nan_included() {
    declare(&[(7001, true, "robot/ranger", "range", "/range", "data")]);
    let dir = std::env::temp_dir().join(format!("ferroc-ros2rec-{}", std::process::id()));
    let path = dir.join("ros2.mcap");
    let values = [1.5, f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 2.25];
    record_values(&path, "robot/ranger/range", &values);
    let rec = recording::Recording::read(&path).unwrap();
    let ros2 = rec
        .ros2_channel("/range")
        .expect("a channel on the ROS 2 topic");
    assert_eq!(
        (
            ros2.message_encoding.as_str(),
            ros2.schema_encoding.as_str(),
            ros2.schema_name.as_str()
        ),
        ("cdr", "ros2msg", "std_msgs/msg/Float64")
    );
    assert_eq!(ros2.schema_data, b"float64 data\n");
    let meta = |k: &str| ros2.metadata.get(k).map(String::as_str);
    assert_eq!(meta("ferroc.port"), Some("robot/ranger/range"));
    assert_eq!(meta("ferroc.form"), Some("ros2"));
    assert_eq!(meta("ferroc.ros2.field"), Some("data"));
    assert_eq!(
        (meta("ferroc.type"), meta("ferroc.unit")),
        (Some("f64"), Some("m"))
    );
    // Every value, bit for bit after the CDR header: non-finite ones too.
    let expected: Vec<Vec<u8>> = (values.iter())
        .map(|x| [[0, 1, 0, 0].as_slice(), &x.to_le_bytes()].concat())
        .collect();
    assert_eq!(
        messages_of(&rec, ros2.id),
        expected.iter().collect::<Vec<_>>()
    );
    let exact = rec
        .exact_channel("robot/ranger/range")
        .expect("still exact");
    assert_eq!(messages_of(&rec, exact.id).len(), values.len());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_subscribed_port_writes_its_topic_s_channel_unless_a_recorded_port_publishes_it() {
    // /heading: subscribed by two recorded inputs (one field, then all of Float64).
    declare(&[
        (7101, false, "robot/steer", "x", "/heading", "x"),
        (7102, false, "robot/show", "heading", "/heading", "data"),
        (7103, false, "robot/echo", "cmd", "/cmd", "data"),
        (7104, true, "robot/drive", "cmd", "/cmd", "data"),
    ]);
    let dir = std::env::temp_dir().join(format!("ferroc-ros2sub-{}", std::process::id()));
    let channels = |file: &str, ports: &[&str]| {
        let path = dir.join(file);
        record_ports(&path, ports, &[0.5]);
        let rec = recording::Recording::read(&path).unwrap();
        let mut ros2: Vec<(String, String)> = (rec.channels.values())
            .filter(|c| c.is_ros2())
            .map(|c| (c.topic.clone(), c.metadata["ferroc.port"].clone()))
            .collect();
        ros2.sort();
        ros2
    };
    let pair = |t: &str, p: &str| (t.to_owned(), p.to_owned());
    // The whole message before one field of it; once per topic.
    assert_eq!(
        channels("sub.mcap", &["robot/steer/x", "robot/show/heading"]),
        [pair("/heading", "robot/show/heading")]
    );
    // Published and subscribed: the publisher's values (it is recorded in another file
    // of this process: the choice is the same in every file).
    assert_eq!(
        channels("pubsub.mcap", &["robot/echo/cmd", "robot/drive/cmd"]),
        [pair("/cmd", "robot/drive/cmd")]
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_port_no_node_publishes_or_subscribes_is_recorded_as_before_even_beside_ros2_nodes() {
    declare(&[(7201, true, "robot/other", "value", "/other", "data")]);
    let dir = std::env::temp_dir().join(format!("ferroc-plainrec-{}", std::process::id()));
    let path = dir.join("plain.mcap");
    record_values(&path, "robot/plain/value", &[1.0, 2.0]);
    let rec = recording::Recording::read(&path).unwrap();
    let forms: Vec<(&str, &str)> = (rec.channels.values())
        .map(|c| (c.topic.as_str(), c.message_encoding.as_str()))
        .collect();
    assert_eq!(
        forms,
        [
            ("robot/plain/value", "postcard"),
            ("robot/plain/value", "json")
        ]
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_timestamp_in_a_message_is_recorded_as_builtin_interfaces_time() {
    use ferroc_runtime::link::ros2::{Ros2Node, Ros2Qos, Ros2Topic};
    use ferroc_runtime::module::ValueTable;
    use ferroc_runtime::port::ConnectOptions;
    let port = "robot/stamper/stamp";
    let node = Ros2Node {
        part: "robot".into(),
        domain: 0,
        namespace: "/".into(),
        name: "robot".into(),
        topics: vec![Ros2Topic {
            id: 7301,
            publish: true,
            port: ("robot/stamper".into(), "stamp".into()),
            model_type: "timestamp".into(),
            topic: "/stamped".into(),
            message: "std_msgs/msg/Header".into(),
            field: Some("stamp".into()),
            qos: Ros2Qos::default(),
            frame_id: String::new(),
        }],
        services: vec![],
        clients: vec![],
        interfaces: vec![],
    };
    ferroc_runtime::link::ros2_wire::add_node(&node).unwrap();
    recording::ros2::add_recorded([port]);
    let table = ValueTable::default();
    let vt = table.get("timestamp").expect("registered");
    let (out, oh) = vt.output("out");
    let (input, ih) = vt.input("in/0", None);
    oh.connect(&ih, ConnectOptions::default()).unwrap();
    let info = ChannelInfo {
        topic: port.into(),
        port: port.into(),
        model_type: "timestamp".into(),
        ..ChannelInfo::default()
    };
    let mut ports = vec![Recorded::new(input, *vt.wire().unwrap(), info)];
    let dir = std::env::temp_dir().join(format!("ferroc-ros2time-{}", std::process::id()));
    let path = dir.join("time.mcap");
    let log = LogFile::open_shared(&path, 1).unwrap();
    out.typed::<Timestamp>().unwrap().publish(Timestamp {
        nanos: 1_500_000_007,
    });
    let (mut exact, mut text) = (Vec::new(), Vec::new());
    record_at(&log, &mut ports, 0, false, &mut exact, &mut text).unwrap();
    drop(log);
    let rec = recording::Recording::read(&path).unwrap();
    let ros2 = rec.ros2_channel("/stamped").expect("a ROS 2 channel");
    // Header: stamp (sec 1, nanosec 500000007), frame_id "" (length 1, the NUL).
    let expected = [
        [0, 1, 0, 0].as_slice(),
        &1i32.to_le_bytes(),
        &500_000_007u32.to_le_bytes(),
        &1u32.to_le_bytes(),
        &[0],
    ]
    .concat();
    assert_eq!(messages_of(&rec, ros2.id), [&expected]);
    let _ = std::fs::remove_dir_all(&dir);
}
