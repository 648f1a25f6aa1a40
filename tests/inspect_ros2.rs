//! `ferroc run --inspect` of a model whose part is a ROS 2 node (issue 29): the node
//! opens its own Zenoh session (rmw_zenoh's configuration, here a loopback port the
//! ROS 2 peer connects to as to its router) beside the inspection server's. While
//! `zenoh-ros2-sdk` (PyPI, a pure-Python rmw_zenoh node we did not write) lists the
//! node's topics, receives `/cmd_vel` and stops the robot through `/enable`,
//! `ferroc inspect` reads the port published as `/cmd_vel` and lists the node's topics.
//!
//! Without a Python that has `zenoh_ros2_sdk` the test skips visibly.

mod common;

use common::Killed;

use common::inspected::{free_port, lines, wait_for_line};
use common::{ferroc, tempdir, test_log_dir};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
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

/// `ferroc run MODEL --inspect` on a free loopback port, the node listening on
/// loopback's `node_port`: the child (killed when dropped) and its inspection address,
/// once it printed its token.
fn start_inspected(name: &str, node_port: u16) -> (Killed, String) {
    let dir = tempdir(name);
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
    (run, address)
}

#[test]
fn an_inspected_run_is_a_ros2_node_the_sdk_sees_while_the_inspector_reads_its_ports() {
    let Some(python) = ferroc_testkit::python(&["zenoh_ros2_sdk"]) else {
        return;
    };
    let node_port = free_port();
    let (mut run, address) = start_inspected("inspect_ros2", node_port);

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

/// `ferroc inspect --list` names, under each port the node publishes or subscribes,
/// its topic with type, QoS and node; no other port gets such a line. The page shows
/// the same (tests/web/inspect_ros2_page.mjs, where a browser is installed).
#[test]
fn the_inspector_lists_which_ports_are_ros2_topics() {
    // Nobody connects to the node: it runs all the same.
    let (_run, address) = start_inspected("inspect_ros2_list", free_port());
    let (code, out, err) = inspect(&address, &["--list"]);
    assert_eq!(code, 0, "{err}");
    let twist = "    out twist: crash_course.Twist\n        ROS 2 publish /cmd_vel (geometry_msgs/msg/Twist; reliable, volatile, depth 10) on node /fragile_bot, domain 0\n";
    assert!(out.contains(twist), "{out}");
    for line in [
        "        ROS 2 publish /ir_front (std_msgs/msg/Float64.data; best-effort, volatile, depth 10) on node /fragile_bot, domain 0",
        "        ROS 2 subscribe /enable (std_msgs/msg/Bool.data; reliable, volatile, depth 10) on node /fragile_bot, domain 0",
    ] {
        assert!(out.contains(line), "{line} not in {out}");
    }
    assert_eq!(out.matches("ROS 2 ").count(), 3, "{out}");

    // The tree's JSON carries them as `ros2` of their module, and only there.
    let (code, out, err) = inspect(&address, &["--list", "--json"]);
    assert_eq!(code, 0, "{err}");
    let all: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    let modules = all["ros2_crash_course/fragile_bot"]["tree"]["modules"]
        .as_array()
        .unwrap();
    let with: Vec<&serde_json::Value> =
        modules.iter().filter(|m| m.get("ros2").is_some()).collect();
    assert_eq!(with.len(), 3, "{out}");
    let twist_out = modules
        .iter()
        .find(|m| m["path"] == "fragile_bot/main/control/twist_out")
        .unwrap();
    assert_eq!(
        twist_out["ros2"],
        serde_json::json!([{"port": "twist", "role": "publish", "name": "/cmd_vel",
            "type": "geometry_msgs/msg/Twist", "node": "/fragile_bot", "domain": 0,
            "qos": {"reliability": "reliable", "durability": "volatile", "depth": 10}}])
    );

    page_shows_ros2_topics(&address);
}

/// The page in a real browser (skips visibly without Chromium and playwright-core).
fn page_shows_ros2_topics(connect: &str) {
    let chromium = std::env::var("FERROC_CHROMIUM").unwrap_or_else(|_| "chromium".into());
    let Some(chromium) = ferroc_testkit::command(&chromium) else {
        return;
    };
    let Some(node_modules) = ferroc_testkit::node_modules(&["playwright-core"]) else {
        return;
    };
    let page = format!("127.0.0.1:{}", free_port());
    let mut web = Command::new(env!("CARGO_BIN_EXE_ferroc"));
    web.args(["inspect", "--serve", &page, "--connect", connect])
        .current_dir(root())
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    let mut web = Killed(web.spawn().expect("ferroc runs"));
    let stderr = lines(web.0.stderr.take().unwrap());
    wait_for_line(&stderr, "the page is on", Duration::from_secs(60));
    let out = Command::new("node")
        .arg(root().join("tests/web/inspect_ros2_page.mjs"))
        .env("FERROC_NODE_MODULES", &node_modules)
        .env("FERROC_CHROMIUM", &chromium)
        .env("FERROC_PAGE_URL", format!("http://{page}/"))
        .output()
        .expect("node runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    println!("{stdout}");
    assert!(
        out.status.success(),
        "the page test failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for step in [
        "/cmd_vel (geometry_msgs",
        "only the node's 3 ports",
        "twist value",
    ] {
        assert!(stdout.contains(step), "missing `{step}` in:\n{stdout}");
    }
}
