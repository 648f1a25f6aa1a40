//! `ferroc_std.Logger` recording into MCAP in lockstep: channels, schemas, counts,
//! exact payloads and log times as the model implies.

mod common;

use common::{add, registry, run_lockstep, scratch};
use ferroc_runtime::builder::Builder;
use ferroc_runtime::module::{Direction, PortGroup, Timestamp, Value};
use ferroc_runtime::port::ConnectOptions;
use ferroc_std::recording::Recording;
use std::path::Path;
use std::time::Duration;

/// Two constants (4.5 and NaN) into a logger; `cycles` of a 10 ms container in
/// lockstep. Returns the recording.
fn record(dir: &Path, period: Duration, cycles: u64) -> Recording {
    let file = dir.join("values.mcap");
    let r = registry();
    let mut b = Builder::new(&r);
    add(
        &mut b,
        "speed",
        "ferroc_std.Constant",
        &[("value", Value::Float(4.5))],
        &[],
    )
    .unwrap();
    add(
        &mut b,
        "odd",
        "ferroc_std.Constant",
        &[("value", Value::Float(f64::NAN))],
        &[],
    )
    .unwrap();
    let ports = [PortGroup::new("in", Direction::In, "f64", Some(2))];
    let params = [
        ("file", Value::Text(file.to_string_lossy().into_owned())),
        ("period", Value::Duration(period)),
    ];
    add(&mut b, "robot/log", "ferroc_std.Logger", &params, &ports).unwrap();
    for (from, to) in [("speed", "in/0"), ("odd", "in/1")] {
        b.connect(
            (from, "value"),
            ("robot/log", to),
            Default::default(),
            ConnectOptions::default(),
        )
        .unwrap();
    }
    run_lockstep(b, &["speed", "odd", "robot/log"], cycles);
    Recording::read(&file).unwrap()
}

const EPOCH: u64 = Timestamp::LOCKSTEP_EPOCH.nanos as u64;
const MS: u64 = 1_000_000;

#[test]
fn every_value_is_recorded_exactly_at_model_time_with_a_json_mirror() {
    let dir = scratch("logger_every_value");
    let rec = record(&dir, Duration::ZERO, 5);
    assert!(
        rec.finished,
        "finished cleanly when the application stopped"
    );
    assert_eq!(rec.damaged, None);
    // Two ports, two channels each (exact and JSON), on the port's path.
    let topics: Vec<(&str, &str)> = rec
        .channels
        .values()
        .map(|c| (c.topic.as_str(), c.message_encoding.as_str()))
        .collect();
    assert_eq!(
        topics,
        [
            ("robot/log/in/0", "postcard"),
            ("robot/log/in/0", "json"),
            ("robot/log/in/1", "postcard"),
            ("robot/log/in/1", "json"),
        ]
    );
    let speed = rec.exact_channel("robot/log/in/0").unwrap();
    assert_eq!(speed.model_type(), "f64");
    assert_eq!(speed.schema_encoding, "ferroc-type");
    assert_eq!(speed.metadata["ferroc.port"], "robot/log/in/0");
    assert_eq!(speed.count, 5, "a constant publishes every cycle");
    assert_eq!(
        (speed.first, speed.last),
        (Some(EPOCH), Some(EPOCH + 40 * MS))
    );
    // Exact payloads: postcard f64 is its 8 little-endian bytes, NaN included.
    let odd = rec.exact_channel("robot/log/in/1").unwrap().id;
    for m in rec.messages.iter().filter(|m| m.channel == odd) {
        let x = f64::from_le_bytes(m.data.as_slice().try_into().unwrap());
        assert!(x.is_nan());
    }
    // The JSON mirror: 4.5 and null (JSON has no NaN), schema allowing null.
    let json = |topic: &str| {
        rec.channels
            .values()
            .find(|c| c.topic == topic && c.message_encoding == "json")
            .unwrap()
    };
    let mirror = json("robot/log/in/1");
    assert_eq!(mirror.schema_encoding, "jsonschema");
    let schema: serde_json::Value = serde_json::from_slice(&mirror.schema_data).unwrap();
    assert_eq!(schema["type"], serde_json::json!(["number", "null"]));
    let texts: Vec<&[u8]> = rec
        .messages
        .iter()
        .filter(|m| m.channel == mirror.id || m.channel == json("robot/log/in/0").id)
        .map(|m| m.data.as_slice())
        .collect();
    assert_eq!(texts[..2], [b"4.5".as_slice(), b"null"]);
}

#[test]
fn a_period_records_at_most_one_value_per_period_and_runs_are_identical() {
    let dir = scratch("logger_period");
    let rec = record(&dir, Duration::from_millis(20), 6);
    let speed = rec.exact_channel("robot/log/in/0").unwrap();
    let times: Vec<u64> = rec
        .messages
        .iter()
        .filter(|m| m.channel == speed.id)
        .map(|m| m.log_time - EPOCH)
        .collect();
    assert_eq!(times, [0, 20 * MS, 40 * MS]);
    // Lockstep: the same file, byte for byte, every run.
    let first = std::fs::read(dir.join("values.mcap")).unwrap();
    record(&dir, Duration::from_millis(20), 6);
    assert_eq!(first, std::fs::read(dir.join("values.mcap")).unwrap());
}
