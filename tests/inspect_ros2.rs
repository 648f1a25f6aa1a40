//! `ferroc run --inspect` of a model whose part is a ROS 2 node (issue 29): the node
//! opens its own Zenoh session (rmw_zenoh's configuration, here a loopback port the
//! ROS 2 peer connects to as to its router) beside the inspection server's. While
//! `zenoh-ros2-sdk` (PyPI, a pure-Python rmw_zenoh node we did not write) lists the
//! node's topics, receives `/cmd_vel` and stops the robot through `/enable`,
//! `ferroc inspect` reads the port published as `/cmd_vel` and lists the node's topics.
//!
//! Without a Python that has `zenoh_ros2_sdk` the test skips visibly.

mod common;

use common::inspected::{free_port, lines, wait_for_line};
use common::{ferroc, tempdir, test_log_dir};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

const MODEL: &str = "models/ros2_crash_course.xml";
/// The port `main/control/twist_out/twist` of the part, published as `/cmd_vel`.
const TWIST: &str = "fragile_bot/main/control/twist_out/twist";

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A Zenoh configuration for the node listening on loopback's `port`.
fn listening_config(dir: &Path, port: u16) -> PathBuf {
    let file = dir.join("zenoh-listen.json5");
    let text = format!(
        "{{ connect: {{ endpoints: [] }},\n  listen: {{ endpoints: [\"tcp/127.0.0.1:{port}\"] }} }}\n"
    );
    std::fs::write(&file, text).unwrap();
    file
}

/// Kills the child when the test ends, however it ends.
struct Killed(Child);

impl Drop for Killed {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn inspect(address: &str, args: &[&str]) -> (i32, String, String) {
    let mut all = vec!["inspect", "--connect", address];
    all.extend_from_slice(args);
    ferroc(&all)
}

/// Asks until the Twist published as /cmd_vel has a value (the inspector's JSON).
fn twist(address: &str) -> serde_json::Value {
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        let (code, out, err) = inspect(address, &["--get", TWIST, "--json"]);
        if code == 0 {
            let answer: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
            if answer["value"].is_object() {
                return answer["value"].clone();
            }
        }
        assert!(Instant::now() < deadline, "{TWIST}: {out} {err}");
        std::thread::sleep(Duration::from_millis(100));
    }
}

#[test]
fn an_inspected_run_is_a_ros2_node_the_sdk_sees_while_the_inspector_reads_its_ports() {
    let Some(python) = ferroc_testkit::python(&["zenoh_ros2_sdk"]) else {
        return;
    };
    let dir = tempdir("inspect_ros2");
    let node_port = free_port();
    let config = listening_config(&dir, node_port);
    let address = format!("127.0.0.1:{}", free_port());
    let mut run = Command::new(env!("CARGO_BIN_EXE_ferroc"));
    run.args(["run", MODEL, "--for", "600s", "-q", "--inspect", &address])
        .env("FERROC_LOG_DIR", test_log_dir())
        .env("ZENOH_SESSION_CONFIG_URI", &config)
        .current_dir(root())
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    let mut run = Killed(run.spawn().expect("ferroc runs"));
    let stderr = lines(run.0.stderr.take().unwrap());
    // The first inspected run of a ROS 2 model builds its runner: minutes.
    wait_for_line(&stderr, "token for changes: ", Duration::from_secs(1500));

    // The inspector reads the port the node publishes, a Twist's fields.
    let value = twist(&address);
    assert!(value["linear"]["x"].is_number(), "{value}");
    assert!(value["angular"]["z"].is_number(), "{value}");

    // The ROS 2 peer sees the node's topics with their types and receives /cmd_vel.
    let peer = Command::new(&python)
        .arg(root().join("tests/ros2/sdk_peer.py"))
        .arg(node_port.to_string())
        .arg(root().join("ros2/interfaces"))
        .arg("25")
        .env(
            "ZENOH_CONFIG_OVERRIDE",
            "listen/endpoints=[\"tcp/127.0.0.1:0\"]",
        )
        .output()
        .unwrap();
    let peer_err = String::from_utf8_lossy(&peer.stderr);
    assert!(peer.status.success(), "{peer_err}");
    let text = String::from_utf8_lossy(&peer.stdout);
    let report: serde_json::Value = serde_json::from_str(text.trim()).expect("one JSON object");
    let topics = report["topics"].as_array().unwrap();
    for (topic, ty) in [
        ("/cmd_vel", "geometry_msgs/msg/Twist"),
        ("/enable", "std_msgs/msg/Bool"),
        ("/ir_front", "std_msgs/msg/Float64"),
    ] {
        let listed = serde_json::json!([topic, [ty]]);
        assert!(topics.contains(&listed), "{listed} not in {text}");
    }
    let samples = report["samples"].as_array().unwrap();
    assert!(samples.len() >= 10, "{text}");
    // The peer's /enable false stopped the robot: the inspector reads a standing Twist.
    let still = twist(&address);
    for v in [&still["linear"], &still["angular"]] {
        for axis in ["x", "y", "z"] {
            assert_eq!(v[axis].as_f64(), Some(0.0), "{still}");
        }
    }
    // The program runs on and still answers.
    assert!(run.0.try_wait().unwrap().is_none(), "the run ended");
    let (code, _, err) = inspect(&address, &["--list"]);
    assert_eq!(code, 0, "{err}");
}
