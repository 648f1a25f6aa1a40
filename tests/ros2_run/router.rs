//! Through ROS 2's router (docs/ros2.md "Running it"): a ROS 2 computer runs
//! `rmw_zenohd` and every node connects to it. Here a Zenoh router of Python
//! `eclipse-zenoh` (`tests/ros2/router.py`: mode `router` on a free loopback port,
//! multicast scouting off) stands in for it; the run connects to it as a node connects
//! to rmw_zenohd, and zenoh-ros2-sdk's node connects to it in Zenoh's client mode, so
//! that nothing reaches it but through the router: the liveliness tokens it lists, the
//! samples it receives, the samples it publishes and its service calls. Neither side
//! knows the other's address.

use super::*;
use std::io::{BufRead, BufReader};
use std::process::Child;

/// The router; dropping it stops it (closing its standard input), also when a test
/// fails.
struct Router {
    child: Child,
    port: u16,
}

impl Router {
    fn start(python: &Path) -> Router {
        let port = free_port();
        let mut child = Command::new(python)
            .arg(root().join("tests/ros2/router.py"))
            .args([port.to_string().as_str(), "60"])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .unwrap();
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .unwrap();
        assert!(
            line.starts_with("ready "),
            "the router did not start: {line:?}"
        );
        Router { child, port }
    }

    fn endpoint(&self) -> String {
        format!("tcp/127.0.0.1:{}", self.port)
    }
}

impl Drop for Router {
    fn drop(&mut self) {
        drop(self.child.stdin.take());
        if self.child.wait().is_err() {
            let _ = self.child.kill();
        }
    }
}

/// Runs `model` for 30 s connected to a router beside the zenoh-ros2-sdk peer
/// `script`, which reaches the router only (client mode): the peer's JSON report and
/// its text. The run records into `dir/run.mcap`.
fn sdk_through_router(
    python: &Path,
    dir: &Path,
    model: &str,
    script: &str,
) -> (serde_json::Value, String) {
    build_runner_of(model, dir);
    let router = Router::start(python);
    let config = zenoh_config(dir, &[&router.endpoint()]);
    let mut peer = sdk_peer(python, router.port, script);
    peer.env("ZENOH_CONFIG_OVERRIDE", "mode=\"client\"");
    let mut run = run_model(model, &config, &["--for", "30s", "--record"]);
    run.arg(dir.join("run.mcap"));
    run_beside(peer, run)
}

/// The crash course's node through the router: the SDK lists its topics with their
/// types, receives /cmd_vel with the commands the run recorded, and its /enable stops
/// the robot.
#[test]
fn zenoh_ros2_sdk_reaches_the_node_s_topics_through_a_zenoh_router() {
    let Some(python) = ferroc_testkit::python(&["zenoh", "zenoh_ros2_sdk"]) else {
        return;
    };
    let dir = tempdir("ros2_router_topics");
    let (report, text) = sdk_through_router(&python, &dir, MODEL, "sdk_peer.py");

    let topics = report["topics"].as_array().unwrap();
    for (topic, ty) in [
        ("/cmd_vel", "geometry_msgs/msg/Twist"),
        ("/ir_front", "std_msgs/msg/Float64"),
        ("/enable", "std_msgs/msg/Bool"),
    ] {
        let listed = serde_json::json!([topic, [ty]]);
        assert!(topics.contains(&listed), "{listed} not in {text}");
    }
    let samples = report["samples"].as_array().unwrap();
    assert!(samples.len() >= 10, "{text}");
    check_values(samples, &dir.join("run.mcap"));
    check_enable(samples, &text);
}

/// A module's service through the router: the SDK lists it with its type, and its
/// client's calls (queries routed by the router) get the module's answers.
#[test]
fn zenoh_ros2_sdk_calls_a_module_s_service_through_a_zenoh_router() {
    let Some(python) = ferroc_testkit::python(&["zenoh", "zenoh_ros2_sdk"]) else {
        return;
    };
    let dir = tempdir("ros2_router_service");
    let (report, text) = sdk_through_router(&python, &dir, SWITCH, "sdk_service_peer.py");

    let listed = serde_json::json!(["/switch_bot/set_enabled", ["std_srvs/srv/SetBool"]]);
    assert!(
        report["services"].as_array().unwrap().contains(&listed),
        "{listed} not in {text}"
    );
    let answer =
        |success: bool, message: &str| serde_json::json!({"success": success, "message": message});
    assert_eq!(
        report["responses"],
        serde_json::json!([answer(true, "disabled"), answer(true, "enabled")]),
        "{text}"
    );
}
