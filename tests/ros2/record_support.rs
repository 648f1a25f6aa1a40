//! What the recording tests of ROS 2 topics share (tests/ros2_record*.rs): a run of
//! `ferroc run` that connects to nobody, and what Python `mcap` and `rosbags` read in a
//! recording (`record_check.py`).
#![allow(dead_code)]

use serde_json::Value as Json;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A Zenoh configuration connecting only to a loopback port nobody listens on.
pub fn nobody(dir: &Path) -> PathBuf {
    let port = ferroc_testkit::free_port();
    let file = dir.join("zenoh-nobody.json5");
    let text = format!(
        "{{ connect: {{ endpoints: [\"tcp/127.0.0.1:{port}\"] }},\n  listen: {{ endpoints: [\"tcp/127.0.0.1:0\"] }} }}\n"
    );
    std::fs::write(&file, text).unwrap();
    file
}

/// `ferroc run MODEL --lockstep --for 4s --log-dir DIR` with `args`, which must succeed:
/// its standard error.
pub fn run(model: &str, dir: &Path, args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_ferroc"))
        .args(["run", model, "-q", "--lockstep", "--for", "4s", "--log-dir"])
        .arg(dir)
        .args(args)
        .env("ZENOH_SESSION_CONFIG_URI", nobody(dir))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{err}");
    err
}

/// What Python `mcap` and `rosbags` read in `file` (`tests/ros2/record_check.py`).
pub fn read(python: &Path, file: &Path) -> Json {
    script(python, "record_check.py", &[file.as_os_str()])
}

/// The JSON `tests/ros2/SCRIPT ARGS…` printed; the script must succeed.
pub fn script(python: &Path, script: &str, args: &[&std::ffi::OsStr]) -> Json {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/ros2")
        .join(script);
    let out = Command::new(python).arg(path).args(args).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{script}: {err}");
    serde_json::from_slice(&out.stdout).expect("one JSON object")
}

pub fn channel<'a>(report: &'a Json, topic: &str, encoding: &str) -> &'a Json {
    let channels = report["channels"].as_array().unwrap();
    (channels.iter())
        .find(|c| c["topic"] == topic && c["message_encoding"] == encoding)
        .unwrap_or_else(|| panic!("no {encoding} channel {topic}: {channels:?}"))
}
