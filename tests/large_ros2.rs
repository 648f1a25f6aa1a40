//! ferroc_std's `Image` and `PointCloud` as ROS 2's `sensor_msgs/msg/Image` and
//! `PointCloud2` (issues 29 and 30, docs/ros2.md "Mapped types"), proven with clients we
//! did not write:
//!
//! - a lockstep run of `tests/large_ros2/camera.xml` recorded with `--record`: Python
//!   `mcap` and `rosbags` read the /image and /points channels (cdr, ros2msg schemas)
//!   with types built only from the schema text, to the values the model sent, the
//!   header filled (model time, the topic's `frame-id=`), the cloud one row; our
//!   `ferroc_std.Player` replays those channels into Image and PointCloud ports, to the
//!   values sent (`tests/large_ros2/replay.xml`);
//! - a bundle's program of the model records the same samples;
//! - `ferroc run` of the same model beside a `zenoh-ros2-sdk` node
//!   (`tests/large_ros2/sdk_image_peer.py`): it lists our topics with their types,
//!   receives our Image and PointCloud, and its Images reach our input; its big-endian
//!   16-bit images, which an Image cannot represent, are refused in a throttled warning
//!   naming the topic while the good ones keep arriving.
//!
//! Without a Python that has the clients the tests skip visibly.

mod common;
#[path = "ros2/record_support.rs"]
mod record_support;

use common::tempdir;
use ferroc_testkit::free_port;
use serde_json::{json, Value as Json};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

const MODEL: &str = "tests/large_ros2/camera.xml";
const REPLAY: &str = "tests/large_ros2/replay.xml";

/// What the model's constants send, as their JSON (and `Dump`'s) form.
const IMAGE: &str = r#"{"width":3,"height":2,"encoding":"rgb8","step":10,"data":[0,1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16,17,18,250]}"#;
const CLOUD: &str = r#"{"fields":[{"name":"x","offset":0,"datatype":7,"count":1},{"name":"y","offset":4,"datatype":7,"count":1},{"name":"z","offset":8,"datatype":7,"count":1}],"point_step":12,"data":[0,0,128,63,0,0,0,64,0,0,64,64,0,0,128,64,0,0,160,64,0,0,192,192]}"#;

/// Where model time starts in a lockstep run (2000-01-01T00:00:00Z), in seconds.
const LOCKSTEP_EPOCH: i64 = 946_684_800;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn parse(text: &str) -> Json {
    serde_json::from_str(text).unwrap()
}

/// The message rosbags should read for the model's image, stamped `header`.
fn image_message(header: Json) -> Json {
    let sent = parse(IMAGE);
    json!({
        "header": header,
        "height": 2, "width": 3, "encoding": "rgb8", "is_bigendian": 0, "step": 10,
        "data": sent["data"],
    })
}

/// The message rosbags should read for the model's cloud: one row of two points.
fn cloud_message(header: Json) -> Json {
    let sent = parse(CLOUD);
    json!({
        "header": header,
        "height": 1, "width": 2, "fields": sent["fields"], "is_bigendian": false,
        "point_step": 12, "row_step": 24, "data": sent["data"], "is_dense": false,
    })
}

/// `ferroc run MODEL -q --lockstep --for 4s --log-dir DIR ARGS…`, connecting to nobody;
/// it must succeed. Its standard output and error.
fn lockstep(model: &str, dir: &Path, args: &[&str]) -> (String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_ferroc"))
        .args(["run", model, "-q", "--lockstep", "--for", "4s", "--log-dir"])
        .arg(dir)
        .args(args)
        .env("ZENOH_SESSION_CONFIG_URI", record_support::nobody(dir))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    assert!(out.status.success(), "{}", text(&out.stderr));
    (text(&out.stdout), text(&out.stderr))
}

#[test]
fn rosbags_reads_recorded_images_and_clouds_as_sensor_msgs_and_our_player_replays_them() {
    let Some(python) = ferroc_testkit::python(&["mcap", "rosbags", "numpy"]) else {
        return;
    };
    let dir = tempdir("large_ros2_record");
    let record = dir.join("large.mcap");
    let (_, err) = lockstep(MODEL, &dir, &["--record", record.to_str().unwrap()]);
    assert!(!err.contains("is not recorded"), "{err}");
    let report = record_support::read(&python, &record);
    assert_recorded_as_sent(&report);

    // Our Player reads the sensor_msgs channels back into an Image and a PointCloud.
    let (out, _) = lockstep(REPLAY, &dir, &[]);
    let (image, cloud) = (parse(IMAGE), parse(CLOUD));
    let mut replayed = 0;
    for line in out.lines() {
        let (label, value) = line.split_once(": in/0 = ").expect("a Dump line");
        let expected = if label == "image" { &image } else { &cloud };
        assert_eq!(&parse(value), expected, "{line}");
        replayed += 1;
    }
    assert!(replayed >= 2 * 50, "{out}");
}

/// A bundle's program of the model registers the two types with their mapping
/// (`register_ros2`) and carries the topics' `frame-id=`: its lockstep recording reads
/// as `ferroc run`'s does.
#[test]
fn a_bundle_s_program_writes_the_same_sensor_msgs() {
    let Some(python) = ferroc_testkit::python(&["mcap", "rosbags", "numpy"]) else {
        return;
    };
    let dir = tempdir("large_ros2_bundle");
    common::bundle_ok(&root().join(MODEL), &dir.join("bundle"));
    let main = std::fs::read_to_string(dir.join("bundle/parts/cam/src/main.rs")).unwrap();
    for line in [
        "registry.register_ros2::<ferroc_std::Image>();",
        "frame_id: \"camera_optical\".into(),",
    ] {
        assert!(main.contains(line), "{line} not in\n{main}");
    }
    let program = common::build_bundle(&dir.join("bundle"))
        .join("debug")
        .join("large_ros2-cam");
    let record = dir.join("bundle.mcap");
    let out = Command::new(program)
        .args(["-q", "--lockstep", "--for", "4s", "--record"])
        .arg(&record)
        .env("ZENOH_SESSION_CONFIG_URI", record_support::nobody(&dir))
        .current_dir(&dir)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success() && !err.contains("not recorded"),
        "{err}"
    );
    assert_recorded_as_sent(&record_support::read(&python, &record));
}

/// The recording of a lockstep run of the model (`report`: what `mcap` and `rosbags`
/// read in it) holds /image and /points as sensor_msgs, every sample the values sent.
fn assert_recorded_as_sent(report: &Json) {
    for (topic, message, port) in [
        ("/image", "sensor_msgs/msg/Image", "cam/main/frame/out/0"),
        (
            "/points",
            "sensor_msgs/msg/PointCloud2",
            "cam/main/cloud/out/0",
        ),
    ] {
        let c = record_support::channel(report, topic, "cdr");
        assert_eq!(c["schema_encoding"], "ros2msg", "{c}");
        assert_eq!(c["schema_name"], message, "{c}");
        assert_eq!(c["metadata"]["ferroc.port"], port, "{c}");
    }

    // rosbags reads every sample to the values sent, stamped with the model time of the
    // cycle that sent it (every 50 ms from the lockstep epoch), in the topic's frame.
    let stamp = |i: usize, frame: &str| {
        let nanos = i as i64 * 50_000_000;
        json!({"stamp": {"sec": LOCKSTEP_EPOCH + nanos / 1_000_000_000,
                         "nanosec": nanos % 1_000_000_000},
               "frame_id": frame})
    };
    let images = report["ros2"]["/image"].as_array().unwrap();
    let clouds = report["ros2"]["/points"].as_array().unwrap();
    assert!(images.len() >= 50, "{} images", images.len());
    assert_eq!(images.len(), clouds.len());
    for (i, (image, cloud)) in images.iter().zip(clouds).enumerate() {
        assert_eq!(
            image,
            &image_message(stamp(i, "camera_optical")),
            "image {i}"
        );
        assert_eq!(cloud, &cloud_message(stamp(i, "lidar")), "cloud {i}");
    }
}

#[test]
fn zenoh_ros2_sdk_receives_our_image_and_cloud_and_its_images_reach_our_input() {
    let Some(python) = ferroc_testkit::python(&["zenoh_ros2_sdk", "numpy"]) else {
        return;
    };
    let dir = tempdir("large_ros2_sdk");
    // The runner is built first (outside the peer's time) by a run of one cycle.
    lockstep(MODEL, &dir, &["--cycles", "1"]);
    let port = free_port();
    let config = dir.join("zenoh-listen.json5");
    std::fs::write(
        &config,
        format!(
            "{{ connect: {{ endpoints: [] }},\n  listen: {{ endpoints: [\"tcp/127.0.0.1:{port}\"] }} }}\n"
        ),
    )
    .unwrap();
    let peer = Command::new(&python)
        .arg(root().join("tests/large_ros2/sdk_image_peer.py"))
        .arg(port.to_string())
        .arg(root().join("ros2/interfaces"))
        .arg("25")
        .env(
            "ZENOH_CONFIG_OVERRIDE",
            "listen/endpoints=[\"tcp/127.0.0.1:0\"]",
        )
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let run = Command::new(env!("CARGO_BIN_EXE_ferroc"))
        .args(["run", MODEL, "-q", "--for", "30s", "--log-dir"])
        .arg(&dir)
        .env("ZENOH_SESSION_CONFIG_URI", &config)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let peer = peer.wait_with_output().unwrap();
    let run = run.wait_with_output().unwrap();
    let text = |o: &Output| {
        (
            String::from_utf8_lossy(&o.stdout).into_owned(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    let ((peer_out, peer_err), (run_out, run_err)) = (text(&peer), text(&run));
    assert!(run.status.success(), "{run_err}");
    assert!(peer.status.success(), "{peer_err}");
    let report = parse(peer_out.trim());

    let topics = report["topics"].as_array().unwrap();
    for (topic, ty) in [
        ("/image", "sensor_msgs/msg/Image"),
        ("/points", "sensor_msgs/msg/PointCloud2"),
        ("/image_in", "sensor_msgs/msg/Image"),
    ] {
        assert!(
            topics.contains(&json!([topic, [ty]])),
            "{topic} {ty} in {topics:?}"
        );
    }
    // Our samples, as rosbags (inside the SDK) reads them; stamped with the wall clock.
    let images = report["images"].as_array().unwrap();
    let clouds = report["clouds"].as_array().unwrap();
    assert_eq!((images.len(), clouds.len()), (3, 3), "{report}");
    for (image, cloud) in images.iter().zip(clouds) {
        let header = |m: &Json, frame: &str| {
            assert_eq!(m["header"]["frame_id"], frame, "{m}");
            assert!(m["header"]["sec"].as_i64().unwrap() > LOCKSTEP_EPOCH, "{m}");
            json!({"stamp": {"sec": m["header"]["sec"], "nanosec": m["header"]["nanosec"]},
                   "frame_id": frame})
        };
        let mut image = image.clone();
        image["header"] = header(&image, "camera_optical");
        assert_eq!(image, image_message(image["header"].clone()));
        let mut cloud = cloud.clone();
        cloud["header"] = header(&cloud, "lidar");
        let mut expected = cloud_message(cloud["header"].clone());
        // The SDK's fields are [name, offset, datatype, count] lists.
        expected["fields"] = json!([["x", 0, 7, 1], ["y", 4, 7, 1], ["z", 8, 7, 1]]);
        assert_eq!(cloud, expected);
    }

    // The SDK's images reached our input, and its big-endian ones were refused, in a
    // warning naming the topic, throttled (the 1st, 10th, 100th …).
    let seen =
        r#"seen: in/0 = {"width":2,"height":2,"encoding":"mono8","step":2,"data":[11,22,33,44]}"#;
    assert!(run_out.lines().any(|l| l == seen), "{run_out}\n{run_err}");
    let refused: Vec<&str> = (run_out.lines().chain(run_err.lines()))
        .filter(|l| l.contains("/image_in") && l.contains("big-endian `mono16`"))
        .collect();
    assert!(
        (1..=3).contains(&refused.len()),
        "{refused:?}\n{run_out}\n{run_err}"
    );
}
