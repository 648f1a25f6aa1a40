//! `ferroc_std.Image` and `ferroc_std.PointCloud` (issue 30, item 2) inside one process
//! and in recordings, through the CLI: a camera thread's values reach a reader through
//! the ports intact, `--record` records them (nothing left out), and `ferroc_std.Player`
//! replays the recording into the same reader, which then prints exactly what it
//! printed live. Across parts: zenoh-link/tests/shm.rs and tests/shm_fallback.rs.
//!
//! In lockstep: the lines do not depend on the machine's speed.

mod common;
use common::{ferroc, tempdir};
use std::path::Path;

/// A 2×2 `rgb8` image whose rows are padded (step 8 > 2 × 3) and a two-point cloud
/// (`x` as f32: 1.0 and 2.0), as JSON: the constants' parameters and what `Dump` prints.
const IMAGE: &str = r#"{"width":2,"height":2,"encoding":"rgb8","step":8,"data":[0,1,2,3,4,5,250,251,10,11,12,13,14,15,252,253]}"#;
const CLOUD: &str = r#"{"fields":[{"name":"x","offset":0,"datatype":7,"count":1}],"point_step":4,"data":[0,0,128,63,0,0,0,64]}"#;

/// A model whose thread sends (`sources`) an image and a point cloud to two `Dump`s.
fn model(dir: &Path, name: &str, sources: &str) -> String {
    let text = format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<application name="{name}" version="1">
  <use library="ferroc_std"/>
  <part name="cam">
    <thread name="main" period="50ms">
{sources}
      <module name="view" type="ferroc_std.Dump">
        <port name="in" dir="in" type="ferroc_std.Image" count="1"/>
        <param name="label">image</param>
      </module>
      <module name="points" type="ferroc_std.Dump">
        <port name="in" dir="in" type="ferroc_std.PointCloud" count="1"/>
        <param name="label">cloud</param>
      </module>
    </thread>
  </part>
  <connect from="cam/main/image/out/0" to="cam/main/view/in/0"/>
  <connect from="cam/main/cloud/out/0" to="cam/main/points/in/0"/>
</application>
"#
    );
    let file = dir.join(format!("{name}.xml"));
    std::fs::write(&file, text).unwrap();
    file.to_str().unwrap().to_owned()
}

/// Runs `model` for 100 ms of model time in lockstep; its standard output and error.
fn run(model: &str, extra: &[&str]) -> (String, String) {
    let mut args = vec!["run", model, "--lockstep", "--for", "100ms", "-q"];
    args.extend_from_slice(extra);
    let (code, out, err) = ferroc(&args);
    assert_eq!(code, 0, "{out}\n{err}");
    (out, err)
}

#[test]
fn images_and_point_clouds_pass_through_ports_and_a_recording_intact() {
    let dir = tempdir("large_values");
    let constant = |name: &str, ty: &str, value: &str| {
        format!(
            r#"      <module name="{name}" type="ferroc_std.Const">
        <port name="out" dir="out" type="{ty}" count="1"/>
        <param name="values">[{value}]</param>
      </module>"#
        )
    };
    let live = model(
        &dir,
        "live",
        &[
            constant("image", "ferroc_std.Image", IMAGE),
            constant("cloud", "ferroc_std.PointCloud", CLOUD),
        ]
        .join("\n"),
    );
    let recording = dir.join("large.mcap");
    let (out, err) = run(&live, &["--record", recording.to_str().unwrap()]);
    // Three cycles (0, 50 and 100 ms): each value arrives intact every cycle.
    let expected: Vec<String> = (0..3)
        .flat_map(|_| {
            [
                format!("image: in/0 = {IMAGE}"),
                format!("cloud: in/0 = {CLOUD}"),
            ]
        })
        .collect();
    let mut lines: Vec<&str> = out.lines().collect();
    lines.sort_unstable();
    let mut sorted = expected.clone();
    sorted.sort_unstable();
    assert_eq!(lines, sorted, "{err}");
    // Both types are recorded (their serde form), nothing left out.
    assert!(!err.contains("--record leaves out"), "{err}");
    let (code, info, e) = ferroc(&["log", "info", recording.to_str().unwrap()]);
    assert_eq!(code, 0, "{e}");
    for channel in [
        "cam/main/image/out/0  [postcard]  type ferroc_std.Image  part cam  3 message(s)",
        "cam/main/cloud/out/0  [postcard]  type ferroc_std.PointCloud  part cam  3 message(s)",
    ] {
        assert!(info.contains(channel), "`{channel}` not in\n{info}");
    }

    // Replayed one message per step into the same readers: the same lines.
    let player = |name: &str, ty: &str, channel: &str| {
        format!(
            r#"      <module name="{name}" type="ferroc_std.Player">
        <port name="out" dir="out" type="{ty}" count="1"/>
        <param name="file">{}</param>
        <param name="channels">{channel}</param>
        <param name="mode">step</param>
      </module>"#,
            recording.display()
        )
    };
    let replay = model(
        &dir,
        "replay",
        &[
            player("image", "ferroc_std.Image", "cam/main/image/out/0"),
            player("cloud", "ferroc_std.PointCloud", "cam/main/cloud/out/0"),
        ]
        .join("\n"),
    );
    let (again, err) = run(&replay, &[]);
    let mut replayed: Vec<&str> = again.lines().collect();
    replayed.sort_unstable();
    assert_eq!(replayed, sorted, "{err}");
}
