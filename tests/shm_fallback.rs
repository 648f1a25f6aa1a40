//! Large values between two part programs of one bundle on this computer (issue 30,
//! items 1–3): a camera part sends a `ferroc_std.Image` and a `ferroc_std.PointCloud`,
//! both above the 4 KiB threshold, to a viewer part that prints them.
//!
//! - With the computer's `/dev/shm`, both links travel by shared memory (the camera's
//!   inspection says so) and no warning is printed.
//! - With no usable shared memory (the camera started in a mount namespace of its own
//!   whose `/dev/shm` is an empty read-only tmpfs, or which has no `/dev/shm` at all,
//!   as in a container without it), the camera warns once and both values take the
//!   network, intact.
//!
//! No assertion depends on speed: the test waits (bounded) for lines.

mod common;

use common::Killed;

use common::inspected::{free_port, lines};
use common::no_shm::{self, NoShm};
use common::{build_bundle, bundle_ok, ferroc, tempdir, test_log_dir};
use ferroc_std::{Image, PointCloud};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::mpsc::Receiver;
use std::time::{Duration, Instant};

const IMAGE: &str = "camera/main/frame/out/0";
const CLOUD: &str = "camera/main/cloud/out/0";
const WARNING: &str = "warning: shared memory is not usable here";

/// The two values as JSON, as the model's constants give them and `Dump` prints them:
/// a 100×60 `mono8` image (6,000 B) and a cloud of 400 points (4,800 B), their bytes a
/// pattern that a torn or reused buffer would break.
fn values() -> (String, String) {
    let image = Image {
        width: 100,
        height: 60,
        encoding: "mono8".into(),
        step: 100,
        data: (0..6000u32)
            .map(|i| (i % 251) as u8)
            .collect::<Vec<_>>()
            .into(),
    };
    let points: Vec<[f32; 3]> = (0..400).map(|i| [i as f32, -(i as f32), 0.5]).collect();
    let cloud = PointCloud::xyz(&points);
    (
        serde_json::to_string(&image).unwrap(),
        serde_json::to_string(&cloud).unwrap(),
    )
}

fn model(dir: &Path, image: &str, cloud: &str) -> PathBuf {
    let text = format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<application name="fallback" version="1">
  <use library="ferroc_std"/>
  <part name="camera" host="localhost">
    <thread name="main" period="50ms">
      <module name="frame" type="ferroc_std.Const">
        <port name="out" dir="out" type="ferroc_std.Image" count="1"/>
        <param name="values">[{image}]</param>
      </module>
      <module name="cloud" type="ferroc_std.Const">
        <port name="out" dir="out" type="ferroc_std.PointCloud" count="1"/>
        <param name="values">[{cloud}]</param>
      </module>
    </thread>
  </part>
  <part name="viewer" host="localhost">
    <thread name="main" period="50ms">
      <module name="image" type="ferroc_std.Dump">
        <port name="in" dir="in" type="ferroc_std.Image" count="1"/>
        <param name="label">image</param>
      </module>
      <module name="points" type="ferroc_std.Dump">
        <port name="in" dir="in" type="ferroc_std.PointCloud" count="1"/>
        <param name="label">cloud</param>
      </module>
    </thread>
  </part>
  <connect from="{IMAGE}" to="viewer/main/image/in/0"/>
  <connect from="{CLOUD}" to="viewer/main/points/in/0"/>
</application>
"#
    );
    let file = dir.join("fallback.xml");
    std::fs::write(&file, text).unwrap();
    file
}

/// The two programs, running freely; the camera started by `camera` (its program
/// given), inspected at `inspect` when given, the viewer with `viewer_args` more. Their outputs: the viewer's standard
/// output and the camera's standard error, line by line.
struct Programs {
    camera: Killed,
    viewer: Killed,
    viewer_out: Receiver<String>,
    viewer_err: Receiver<String>,
    camera_err: Receiver<String>,
}

fn start(bin: &Path, mut camera: Command, viewer_args: &[&str], inspect: Option<&str>) -> Programs {
    let addresses = [free_port(), free_port()].map(|p| format!("127.0.0.1:{p}"));
    let args = |command: &mut Command, listen: &str| {
        command
            .env("FERROC_LOG_DIR", test_log_dir())
            .args(["-q", "--for", "600s", "--listen", listen])
            .args(["--peer", &format!("camera={}", addresses[0])])
            .args(["--peer", &format!("viewer={}", addresses[1])]);
    };
    args(&mut camera, &addresses[0]);
    if let Some(inspect) = inspect {
        camera.args(["--inspect", inspect]);
    }
    camera.stdout(Stdio::null()).stderr(Stdio::piped());
    let mut camera = Killed(camera.spawn().expect("the camera starts"));
    let mut viewer = Command::new(bin.join("fallback-viewer"));
    args(&mut viewer, &addresses[1]);
    viewer.args(viewer_args);
    viewer.stdout(Stdio::piped()).stderr(Stdio::piped());
    let mut viewer = Killed(viewer.spawn().expect("the viewer starts"));
    Programs {
        viewer_out: lines(viewer.0.stdout.take().unwrap()),
        viewer_err: lines(viewer.0.stderr.take().unwrap()),
        camera_err: lines(camera.0.stderr.take().unwrap()),
        camera,
        viewer,
    }
}

impl Programs {
    /// Waits (bounded) until the viewer printed three images and three clouds; every
    /// line it printed must be one of the two values, intact.
    fn both_arrive_intact(&self, image: &str, cloud: &str) {
        let (image, cloud) = (
            format!("image: in/0 = {image}"),
            format!("cloud: in/0 = {cloud}"),
        );
        let deadline = Instant::now() + Duration::from_secs(120);
        let (mut images, mut clouds) = (0, 0);
        while images < 3 || clouds < 3 {
            let left = deadline.saturating_duration_since(Instant::now());
            let line = self.viewer_out.recv_timeout(left).unwrap_or_else(|_| {
                let err: Vec<String> = self.viewer_err.try_iter().collect();
                panic!(
                    "the viewer printed {images} images and {clouds} clouds; its errors: {err:#?}"
                )
            });
            match line {
                l if l == image => images += 1,
                l if l == cloud => clouds += 1,
                l => panic!("not a value the camera sent: {l:.200}"),
            }
        }
    }

    /// Stops both programs and returns what the camera wrote on standard error.
    fn stop(self) -> Vec<String> {
        let Programs {
            camera,
            viewer,
            camera_err,
            ..
        } = self;
        drop((camera, viewer));
        camera_err.iter().collect()
    }
}

/// How each of the camera's two links travels, from its inspection (bounded wait
/// until both carried values).
fn transport(inspect: &str) -> Vec<(String, String)> {
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        let (code, out, err) = ferroc(&["inspect", "--connect", inspect, "--list", "--json"]);
        if code == 0 {
            let all: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
            let links = all["fallback/camera"]["transport"]["links"].clone();
            let links: Vec<(String, String, u64)> = links
                .as_array()
                .into_iter()
                .flatten()
                .map(|l| {
                    let n = |k: &str| l[k].as_u64().unwrap_or(0);
                    (
                        l["output"].as_str().unwrap_or("").to_owned(),
                        l["by"].as_str().unwrap_or("").to_owned(),
                        n("shared_memory") + n("network"),
                    )
                })
                .collect();
            if links.len() == 2 && links.iter().all(|l| l.2 > 2) {
                return links.into_iter().map(|(o, by, _)| (o, by)).collect();
            }
        }
        assert!(Instant::now() < deadline, "{code}: {out:.2000}\n{err}");
        std::thread::sleep(Duration::from_millis(200));
    }
}

#[test]
fn without_usable_shared_memory_large_values_take_the_network_with_one_warning() {
    let dir = tempdir("shm_fallback");
    let (image, cloud) = values();
    let model = model(&dir, &image, &cloud);
    bundle_ok(&model, &dir.join("bundle"));
    let bin = build_bundle(&dir.join("bundle")).join("debug");
    let camera = bin.join("fallback-camera");

    // The computer's shared memory: both links use it, silently.
    let inspect = format!("127.0.0.1:{}", free_port());
    let programs = start(&bin, Command::new(&camera), &[], Some(&inspect));
    programs.both_arrive_intact(&image, &cloud);
    let by = transport(&inspect);
    assert_eq!(
        by,
        [
            (IMAGE.to_owned(), "shared memory".to_owned()),
            (CLOUD.to_owned(), "shared memory".to_owned())
        ]
    );
    let err = programs.stop();
    assert!(err.iter().all(|l| !l.contains("warning")), "{err:#?}");

    // A reader without shared memory (as on another computer, or a client without
    // it): the camera still puts its values in its pool, and Zenoh sends that reader
    // their bytes, intact; nobody warns.
    let off = dir.join("off.json5");
    std::fs::write(&off, "{ transport: { shared_memory: { enabled: false } } }").unwrap();
    let off = ["--zenoh-config", off.to_str().unwrap()];
    let programs = start(&bin, Command::new(&camera), &off, None);
    programs.both_arrive_intact(&image, &cloud);
    let err = programs.stop();
    assert!(err.iter().all(|l| !l.contains("warning")), "{err:#?}");

    // None usable: one warning, then both values over the network, intact; with a
    // read-only /dev/shm and with none at all.
    for how in [NoShm::ReadOnly, NoShm::Missing] {
        let Some(unshared) = no_shm::command(how, &camera) else {
            return;
        };
        falls_back_with_one_warning(&bin, unshared, &image, &cloud, how);
    }
}

/// The camera started by `camera` (without usable shared memory, `how`) sends both
/// values over the network, intact, after exactly one warning.
fn falls_back_with_one_warning(bin: &Path, camera: Command, image: &str, cloud: &str, how: NoShm) {
    let inspect = format!("127.0.0.1:{}", free_port());
    let programs = start(bin, camera, &[], Some(&inspect));
    programs.both_arrive_intact(image, cloud);
    let by = transport(&inspect);
    assert_eq!(
        by,
        [
            (IMAGE.to_owned(), "network".to_owned()),
            (CLOUD.to_owned(), "network".to_owned())
        ],
        "{how:?}"
    );
    let err = programs.stop();
    let warnings: Vec<&String> = err.iter().filter(|l| l.contains("warning")).collect();
    assert_eq!(warnings.len(), 1, "{how:?}: {err:#?}");
    assert!(warnings[0].starts_with(WARNING), "{how:?}: {err:#?}");
    assert!(
        warnings[0].contains(
            "links between parts on this computer travel over the network. help: check \
             that /dev/shm is mounted"
        ),
        "{how:?}: {err:#?}"
    );
}
