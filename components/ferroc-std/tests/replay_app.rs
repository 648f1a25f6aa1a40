//! Record, then replay in lockstep: `ferroc_std.Player` gives the controller the
//! recorded inputs bit for bit at the same model instants, so its outputs equal the
//! original run's; a recording that does not fit the outputs is refused up front.

mod common;

use common::{add, registry, run_lockstep, scratch};
use ferroc_runtime::builder::{Builder, Conversion};
use ferroc_runtime::module::{Direction, PortGroup, Value};
use ferroc_runtime::port::ConnectOptions;
use ferroc_std::recording::Recording;
use std::path::Path;

fn text(p: &Path) -> Value {
    Value::Text(p.to_string_lossy().into_owned())
}

fn connect(b: &mut Builder<'_>, from: (&str, &str), to: (&str, &str), scale: f64) {
    b.connect(
        from,
        to,
        Conversion::linear(scale, 0.0),
        ConnectOptions::default(),
    )
    .unwrap();
}

/// The "sensor": a clock's tick (u64); the "controller": a Scale of tick/10 (f64,
/// factor 3) whose output and input are logged: in/0 the sensor, in/1 the command.
fn live(file: &Path) {
    let r = registry();
    let mut b = Builder::new(&r);
    add(&mut b, "sensor", "ferroc_std.Clock", &[], &[]).unwrap();
    add_controller_and_log(&mut b, file, ("sensor", "tick"));
    run_lockstep(b, &["sensor", "controller", "log"], 8);
}

fn add_controller_and_log(b: &mut Builder<'_>, file: &Path, sensor: (&str, &str)) {
    add(
        b,
        "controller",
        "ferroc_std.Scale",
        &[("factor", Value::Float(3.0))],
        &[],
    )
    .unwrap();
    add(
        b,
        "log",
        "ferroc_std.Logger",
        &[("file", text(file))],
        &[PortGroup::new("in", Direction::In, "f64", Some(2))],
    )
    .unwrap();
    connect(b, sensor, ("controller", "input"), 0.1);
    connect(b, sensor, ("log", "in/0"), 1.0);
    connect(b, ("controller", "output"), ("log", "in/1"), 1.0);
}

fn replay(recorded: &Path, file: &Path, mode: &str) {
    let r = registry();
    let mut b = Builder::new(&r);
    add(
        &mut b,
        "player",
        "ferroc_std.Player",
        &[
            ("file", text(recorded)),
            ("channels", Value::Text("log/in/0".into())),
            ("mode", Value::Text(mode.into())),
        ],
        &[PortGroup::new("out", Direction::Out, "f64", Some(1))],
    )
    .unwrap();
    add_controller_and_log(&mut b, file, ("player", "out/0"));
    run_lockstep(b, &["player", "controller", "log"], 8);
}

/// (log time, payload) of the exact channel of `topic`.
fn messages(rec: &Recording, topic: &str) -> Vec<(u64, Vec<u8>)> {
    let id = rec.exact_channel(topic).unwrap().id;
    rec.messages
        .iter()
        .filter(|m| m.channel == id)
        .map(|m| (m.log_time, m.data.clone()))
        .collect()
}

#[test]
fn replay_in_lockstep_gives_identical_inputs_and_controller_outputs() {
    let dir = scratch("replay_identical");
    let (original, replayed) = (dir.join("live.mcap"), dir.join("replayed.mcap"));
    live(&original);
    replay(&original, &replayed, "recorded");
    let (a, b) = (
        Recording::read(&original).unwrap(),
        Recording::read(&replayed).unwrap(),
    );
    let sensor = messages(&a, "log/in/0");
    assert_eq!(sensor.len(), 8);
    // The ticks 1..=8 as f64, exactly.
    let ticks: Vec<f64> = sensor
        .iter()
        .map(|(_, d)| f64::from_le_bytes(d.as_slice().try_into().unwrap()))
        .collect();
    assert_eq!(ticks, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0]);
    assert_eq!(
        messages(&b, "log/in/0"),
        sensor,
        "inputs bit for bit, same instants"
    );
    assert_eq!(
        messages(&b, "log/in/1"),
        messages(&a, "log/in/1"),
        "same commands"
    );
}

#[test]
fn step_mode_plays_one_message_per_step() {
    let dir = scratch("replay_step");
    let (original, replayed) = (dir.join("live.mcap"), dir.join("replayed.mcap"));
    live(&original);
    replay(&original, &replayed, "step");
    let b = Recording::read(&replayed).unwrap();
    assert_eq!(messages(&b, "log/in/0").len(), 8);
}

fn refusal(recorded: &Path, channels: &str, ty: &str) -> String {
    let r = registry();
    let mut b = Builder::new(&r);
    add(
        &mut b,
        "player",
        "ferroc_std.Player",
        &[
            ("file", text(recorded)),
            ("channels", Value::Text(channels.into())),
        ],
        &[PortGroup::new("out", Direction::Out, ty, Some(1))],
    )
    .unwrap_err()
    .to_string()
}

#[test]
fn a_missing_channel_a_wrong_type_or_a_missing_file_is_refused_before_the_run() {
    let dir = scratch("replay_refused");
    let original = dir.join("live.mcap");
    live(&original);
    let e = refusal(&original, "log/in/9", "f64");
    assert!(e.contains("has no channel `log/in/9`"), "{e}");
    assert!(e.contains("its channels are: log/in/0, log/in/1"), "{e}");
    let e = refusal(&original, "log/in/0", "u32");
    assert!(
        e.contains("output `out/0` has type `u32`, but the channel `log/in/0`"),
        "{e}"
    );
    assert!(e.contains("recorded as `f64`"), "{e}");
    let e = refusal(&dir.join("nothing.mcap"), "log/in/0", "f64");
    assert!(
        e.contains("cannot read") && e.contains("nothing.mcap"),
        "{e}"
    );
    let e = refusal(&original, "log/in/0, log/in/1", "f64");
    assert!(e.contains("names 2 topic(s) for 1 output(s)"), "{e}");
}

#[test]
fn a_recording_cut_mid_chunk_replays_up_to_the_cut() {
    let dir = scratch("replay_cut");
    let original = dir.join("live.mcap");
    live(&original);
    let bytes = std::fs::read(&original).unwrap();
    // Every cut of the file reads without a panic; cut inside the data, the messages
    // before the cut are kept and the damage is reported.
    for len in (0..bytes.len()).step_by(7) {
        match Recording::parse(&bytes[..len]) {
            Ok(rec) => assert!(rec.messages.len() <= 32, "8 cycles × 2 ports × 2 forms"),
            Err(e) => assert!(e.contains("MCAP"), "{e}"),
        }
    }
    let cut = dir.join("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let rec = Recording::read(&cut).unwrap();
    assert!(!rec.finished);
    assert!(rec.damaged.is_some());
    // Still replayable: the player is created and replays what is there.
    let replayed = dir.join("replayed.mcap");
    let r = registry();
    let mut b = Builder::new(&r);
    add(
        &mut b,
        "player",
        "ferroc_std.Player",
        &[
            ("file", text(&cut)),
            ("channels", Value::Text("log/in/0".into())),
        ],
        &[PortGroup::new("out", Direction::Out, "f64", Some(1))],
    )
    .unwrap();
    add_controller_and_log(&mut b, &replayed, ("player", "out/0"));
    run_lockstep(b, &["player", "controller", "log"], 8);
    let n = messages(&Recording::read(&replayed).unwrap(), "log/in/0").len();
    assert_eq!(n, messages(&rec, "log/in/0").len());
}

/// Where the first chunk's records end in an MCAP file (the byte after its last
/// record): the magic, the header record, records before it (the `ferroc.run`
/// metadata), then the first chunk.
fn end_of_first_chunk(bytes: &[u8]) -> usize {
    let record_len = |at: usize| u64::from_le_bytes(bytes[at + 1..at + 9].try_into().unwrap());
    let mut at = 8;
    while bytes[at] != 0x06 {
        assert!(at + 9 < bytes.len(), "no chunk in the recording");
        at += 9 + record_len(at) as usize;
    }
    at + 9 + record_len(at) as usize
}

/// Issue 27 item 7: in bit-flipped files the reader delivered flipped values (this
/// test failed so before the fix: checksums were not verified). Every single-bit flip
/// of a finished recording is now refused as corrupted, or reads exactly the
/// original messages (a flip the reader never depends on, like the end magic).
#[test]
fn every_bit_flip_is_refused_or_harmless() {
    let dir = scratch("replay_flipped");
    let original = dir.join("live.mcap");
    live(&original);
    let bytes = std::fs::read(&original).unwrap();
    let clean = Recording::parse(&bytes).unwrap();
    assert!(clean.finished && clean.corrupt.is_empty());
    let (mut refused, mut flipped) = (0, bytes.clone());
    for at in 8..bytes.len() {
        let bit = 1u8 << (at % 8);
        flipped[at] ^= bit;
        match Recording::parse(&flipped) {
            Err(e) => {
                assert!(e.contains("is corrupted: "), "byte {at}: {e}");
                refused += 1;
            }
            Ok(rec) => assert_eq!(rec.messages, clean.messages, "byte {at} flipped"),
        }
        flipped[at] ^= bit;
    }
    assert!(
        refused > bytes.len() * 9 / 10,
        "{refused} of {}",
        bytes.len()
    );
    // A flip inside the first chunk's records: the chunk is named.
    flipped[end_of_first_chunk(&bytes) - 1] ^= 1;
    let e = Recording::parse(&flipped).unwrap_err();
    assert!(
        e.contains("is corrupted: chunk 1 (the record at byte ")
            && e.contains("does not match its CRC (saved "),
        "{e}"
    );
}

/// Issue 27 item 7: the Player refuses a corrupted recording, naming the chunk (it
/// replayed the flipped value before the fix); `checksums="ignore"` replays it.
#[test]
fn the_player_refuses_a_corrupted_recording_unless_told_otherwise() {
    let dir = scratch("replay_corrupted");
    let original = dir.join("live.mcap");
    live(&original);
    let mut bytes = std::fs::read(&original).unwrap();
    let at = end_of_first_chunk(&bytes) - 1;
    bytes[at] ^= 0x10;
    let corrupted = dir.join("corrupted.mcap");
    std::fs::write(&corrupted, &bytes).unwrap();
    let e = refusal(&corrupted, "log/in/0", "f64");
    assert!(e.contains("corrupted.mcap` is corrupted: chunk 1"), "{e}");
    assert!(e.contains("checksums=\"ignore\""), "{e}");
    let r = registry();
    let mut b = Builder::new(&r);
    let params = [
        ("file", text(&corrupted)),
        ("channels", Value::Text("log/in/0".into())),
        ("checksums", Value::Text("ignore".into())),
    ];
    let out = [PortGroup::new("out", Direction::Out, "f64", Some(1))];
    add(&mut b, "player", "ferroc_std.Player", &params, &out).unwrap();
}
