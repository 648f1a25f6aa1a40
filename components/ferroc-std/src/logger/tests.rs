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

/// A ROS 2 wire for the tests: a value (JSON `x`) is the message `test_msgs/msg/X` of
/// one float64, little-endian after the CDR header; anything else does not fit.
struct FakeWire;

impl ferroc_runtime::link::ros2_wire::Ros2Wire for FakeWire {
    fn schema(&self, message: &str) -> Result<String, String> {
        match message {
            "test_msgs/msg/X" => Ok("float64 x\n".into()),
            other => Err(format!("unknown message type `{other}`")),
        }
    }
    fn encode(&self, _: &str, _: Option<&str>, json: &[u8]) -> Result<Vec<u8>, String> {
        let x: f64 = serde_json::from_slice(json).map_err(|e| e.to_string())?;
        if x < 0.0 {
            return Err("negative".into());
        }
        Ok([[0, 1, 0, 0].as_slice(), &x.to_le_bytes()].concat())
    }
    fn decode(&self, _: &str, _: Option<&str>, cdr: &[u8]) -> Result<Vec<u8>, String> {
        let x = cdr.get(4..12).ok_or("short")?;
        let x = f64::from_le_bytes(x.try_into().map_err(|_| "short")?);
        serde_json::to_vec(&x).map_err(|e| e.to_string())
    }
}

/// Records `values` of an f64 output at `port` (a log time each) into `path`.
fn record_values(path: &std::path::Path, port: &str, values: &[f64]) {
    use ferroc_runtime::module::ValueTable;
    use ferroc_runtime::port::ConnectOptions;
    let table = ValueTable::default();
    let vt = table.get("f64").expect("registered");
    let (out, oh) = vt.output("out");
    let (input, ih) = vt.input("in/0", None);
    oh.connect(&ih, ConnectOptions::default()).unwrap();
    let info = ChannelInfo {
        topic: port.into(),
        port: port.into(),
        part: "robot".into(),
        model_type: "f64".into(),
        unit: "m".into(),
        ..ChannelInfo::default()
    };
    let mut ports = vec![Recorded::new(input, *vt.wire().unwrap(), info)];
    let log = LogFile::open_shared(path, 1).unwrap();
    let (mut exact, mut text) = (Vec::new(), Vec::new());
    for (k, x) in values.iter().enumerate() {
        out.typed::<f64>().unwrap().publish(*x);
        record_at(
            &log,
            &mut ports,
            k as u64 * 1000,
            true,
            &mut exact,
            &mut text,
        )
        .unwrap();
    }
}

#[test]
fn a_port_published_as_a_ros2_topic_gets_a_cdr_channel_with_its_ros2msg_schema() {
    use ferroc_runtime::link::ros2::{Ros2Qos, Ros2Topic};
    use ferroc_runtime::link::ros2_wire;
    ros2_wire::install(std::sync::Arc::new(FakeWire));
    ros2_wire::add_topics(&[Ros2Topic {
        id: 7001,
        publish: true,
        port: ("robot/ranger".into(), "range".into()),
        model_type: "f64".into(),
        topic: "/range".into(),
        message: "test_msgs/msg/X".into(),
        field: Some("x".into()),
        qos: Ros2Qos::default(),
    }]);
    let dir = std::env::temp_dir().join(format!("ferroc-ros2rec-{}", std::process::id()));
    let path = dir.join("ros2.mcap");
    // -1 does not fit the message: left out of the ROS 2 channel only.
    record_values(&path, "robot/ranger/range", &[1.5, -1.0, 2.25]);
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
        ("cdr", "ros2msg", "test_msgs/msg/X")
    );
    assert_eq!(ros2.schema_data, b"float64 x\n");
    let meta = |k: &str| ros2.metadata.get(k).map(String::as_str);
    assert_eq!(meta("ferroc.port"), Some("robot/ranger/range"));
    assert_eq!(meta("ferroc.form"), Some("ros2"));
    assert_eq!(meta("ferroc.ros2.field"), Some("x"));
    assert_eq!(
        (meta("ferroc.type"), meta("ferroc.unit")),
        (Some("f64"), Some("m"))
    );
    let cdr: Vec<&Vec<u8>> = (rec.messages.iter())
        .filter(|m| m.channel == ros2.id)
        .map(|m| &m.data)
        .collect();
    let expected: Vec<Vec<u8>> = [1.5f64, 2.25]
        .iter()
        .map(|x| [[0, 1, 0, 0].as_slice(), &x.to_le_bytes()].concat())
        .collect();
    assert_eq!(cdr, expected.iter().collect::<Vec<_>>());
    let exact = rec
        .exact_channel("robot/ranger/range")
        .expect("still exact");
    assert_eq!(
        rec.messages
            .iter()
            .filter(|m| m.channel == exact.id)
            .count(),
        3
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_port_no_node_publishes_is_recorded_as_before_even_beside_ros2_nodes() {
    ferroc_runtime::link::ros2_wire::install(std::sync::Arc::new(FakeWire));
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
