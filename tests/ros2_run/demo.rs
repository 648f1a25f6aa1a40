//! The ROS 2 demo (`models/ros2_demo.xml`, docs/ros2.md "The demo") beside a ROS 2 node
//! of `zenoh-ros2-sdk` (`tests/ros2/sdk_demo_peer.py`; its CDR is `rosbags`'): its topic
//! listing shows the six topics with their types, its subscribers receive /cmd_vel,
//! /scan and /odom with the values the run recorded (matched by their header stamps)
//! and /tf (on the key of rosbags' own hash of ROS 2 Jazzy's tf2_msgs/msg/TFMessage, of
//! which the model brings the definition), its /enable stops the robot and its
//! /goal_pose sends it to the goal.

use super::*;

const DEMO: &str = "models/ros2_demo.xml";

/// The recorded values of a channel, in order. `ferroc log cat` prints each as its
/// JSON text escaped (`\"`): read as the body of a JSON string first.
fn recorded_json(file: &Path, channel: &str) -> Vec<serde_json::Value> {
    let (code, out, err) = ferroc(&["log", "cat", file.to_str().unwrap(), "--channel", channel]);
    assert_eq!(code, 0, "{err}");
    let value = |line: &str| {
        let escaped = line.split_once(' ').unwrap().1;
        let text: String = serde_json::from_str(&format!("\"{escaped}\"")).unwrap();
        serde_json::from_str(&text).unwrap()
    };
    out.lines().map(value).collect()
}

/// A ROS 2 header stamp (`sec`, `nanosec`) as ferroc's `Timestamp::nanos`.
fn nanos(stamp: &serde_json::Value) -> i64 {
    stamp["sec"].as_i64().unwrap() * 1_000_000_000 + stamp["nanosec"].as_i64().unwrap()
}

/// A JSON number as the `f32` it was (both sides print an `f32` as the shortest decimal
/// or as its exact widening to `f64`).
fn f32_of(v: &serde_json::Value) -> f32 {
    v.as_f64().unwrap() as f32
}

/// `ferroc check` of the demo, in `models/`, with the model from standard input when
/// `text` is given: (exit code, findings in short form).
fn check_demo(text: Option<&str>) -> (Option<i32>, String) {
    use std::io::Write;
    let mut child = Command::new(env!("CARGO_BIN_EXE_ferroc"))
        .args(["check", if text.is_some() { "-" } else { "ros2_demo.xml" }])
        .args(["--format", "short"])
        .current_dir(root().join("models"))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    stdin.write_all(text.unwrap_or("").as_bytes()).unwrap();
    drop(stdin);
    let out = child.wait_with_output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout) + String::from_utf8_lossy(&out.stderr);
    (out.status.code(), text.into_owned())
}

/// The demo checks with notes only (no finding of area R), and the same model with /tf
/// declared as the wrong message and rviz2 publishing another topic than /goal_pose has
/// both found before anything runs.
#[test]
fn the_demo_checks_clean_and_a_wrong_message_or_a_missing_publisher_is_found() {
    let (code, out) = check_demo(None);
    assert_eq!(code, Some(0), "{out}");
    assert!(!out.contains("error") && !out.contains("warning"), "{out}");
    assert!(!out.contains("[R1"), "{out}");
    let model = std::fs::read_to_string(root().join(DEMO)).unwrap();
    let tf = r#"topic="/tf" type="tf2_msgs/msg/TFMessage""#;
    let goal = r#"<publish topic="/goal_pose""#;
    assert!(model.contains(tf) && model.contains(goal));
    let broken = (model.replace(
        tf,
        r#"topic="/tf" type="geometry_msgs/msg/TransformStamped""#,
    ))
    .replace(goal, r#"<publish topic="/goal""#);
    let (code, out) = check_demo(Some(&broken));
    assert_eq!(code, Some(1), "{out}");
    assert!(
        out.contains("error[R102]: port `tf` (`crash_course.TFMessage`)"),
        "{out}"
    );
    assert!(
        out.contains("warning[R107]: nothing publishes `/goal_pose`"),
        "{out}"
    );
}

#[test]
fn zenoh_ros2_sdk_sees_the_demo_s_topics_receives_scan_and_odom_and_sets_a_goal() {
    let Some(python) = ferroc_testkit::python(&["zenoh_ros2_sdk"]) else {
        return;
    };
    let dir = tempdir("ros2_demo");
    build_runner_of(DEMO, &dir);
    // The run listens; the SDK's node connects to it as to its router.
    let port = free_port();
    let config = listening_config(&dir, port);
    let peer = sdk_peer(&python, port, "sdk_demo_peer.py");
    let record = dir.join("run.mcap");
    let mut run = run_model(DEMO, &config, &["--for", "30s", "--record"]);
    run.arg(&record);
    let (report, text) = run_beside(peer, run);

    let topics = report["topics"].as_array().unwrap();
    for (topic, ty) in [
        ("/cmd_vel", "geometry_msgs/msg/Twist"),
        ("/scan", "sensor_msgs/msg/LaserScan"),
        ("/odom", "nav_msgs/msg/Odometry"),
        ("/tf", "tf2_msgs/msg/TFMessage"),
        ("/goal_pose", "geometry_msgs/msg/PoseStamped"),
        ("/enable", "std_msgs/msg/Bool"),
    ] {
        let listed = serde_json::json!([topic, [ty]]);
        assert!(topics.contains(&listed), "{listed} not in {text}");
    }
    let twists = report["samples"].as_array().unwrap();
    assert!(twists.len() >= 10, "{text}");
    check_values(twists, &record);
    check_enable(twists, &text);
    check_scans(&report, &record, &text);
    check_odoms(&report, &record, &text);
    check_tf(&report, &text);
    check_goal(&report, &record, &text);
}

/// Every scan: 360 rays from −π, 1° apart, in base_link, every range within
/// range_min..range_max; the first ones range for range as the run recorded them.
fn check_scans(report: &serde_json::Value, record: &Path, text: &str) {
    let scans = report["scans"].as_array().unwrap();
    assert!(scans.len() >= 10, "too few scans: {text}");
    let recorded = recorded_json(record, "fragile_bot/main/simulation/laser/scan");
    let increment = std::f64::consts::TAU / 360.0;
    for s in scans {
        assert_eq!(s["frame_id"], "base_link", "{s}");
        assert_eq!(s["count"], 360, "{s}");
        assert_eq!(s["intensities"], 0, "{s}");
        assert_eq!(f32_of(&s["angle_min"]), -std::f64::consts::PI as f32, "{s}");
        assert_eq!(f32_of(&s["angle_increment"]), increment as f32, "{s}");
        let max = -std::f64::consts::PI + 359.0 * increment;
        assert_eq!(f32_of(&s["angle_max"]), max as f32, "{s}");
        assert_eq!(
            (f32_of(&s["range_min"]), f32_of(&s["range_max"])),
            (0.05, 12.0)
        );
        assert_eq!(f32_of(&s["scan_time"]), 0.04, "{s}");
        assert!(
            f32_of(&s["min"]) >= 0.05 && f32_of(&s["max"]) <= 12.0,
            "{s}"
        );
    }
    let mut compared = 0;
    for s in scans.iter().filter(|s| s.get("ranges").is_some()) {
        let stamp = nanos(&s["stamp"]);
        let Some(r) = (recorded.iter()).find(|r| r["header"]["stamp"]["nanos"] == stamp) else {
            panic!("no recorded scan stamped {stamp}: {s}");
        };
        let ours: Vec<f32> = (r["ranges"].as_array().unwrap().iter())
            .map(f32_of)
            .collect();
        let theirs: Vec<f32> = (s["ranges"].as_array().unwrap().iter())
            .map(f32_of)
            .collect();
        assert_eq!(ours, theirs, "the scan stamped {stamp}");
        compared += 1;
    }
    assert!(compared >= 10, "{text}");
}

/// Every odometry message: odom → base_link, the pose and velocities the run recorded
/// for its stamp, the yaw as a unit quaternion about z, 36 covariances each.
fn check_odoms(report: &serde_json::Value, record: &Path, text: &str) {
    let odoms = report["odoms"].as_array().unwrap();
    assert!(odoms.len() >= 10, "too few odometry messages: {text}");
    let recorded = recorded_json(record, "fragile_bot/main/simulation/odometry/odom");
    for o in odoms {
        assert_eq!(o["frame_id"], "odom", "{o}");
        assert_eq!(o["child_frame_id"], "base_link", "{o}");
        assert_eq!(o["covariance"], serde_json::json!([36, 36]), "{o}");
        let stamp = nanos(&o["stamp"]);
        let Some(r) = (recorded.iter()).find(|r| r["header"]["stamp"]["nanos"] == stamp) else {
            panic!("no recorded odometry stamped {stamp}: {o}");
        };
        let pose = &r["pose"]["pose"];
        let (p, q) = (&pose["position"], &pose["orientation"]);
        assert_eq!(
            o["position"],
            serde_json::json!([p["x"], p["y"], p["z"]]),
            "{o}"
        );
        assert_eq!(
            o["orientation"],
            serde_json::json!([q["x"], q["y"], q["z"], q["w"]]),
            "{o}"
        );
        let twist = &r["twist"]["twist"];
        assert_eq!(o["linear"][0], twist["linear"]["x"], "{o}");
        assert_eq!(o["angular"][2], twist["angular"]["z"], "{o}");
        let q: Vec<f64> = (o["orientation"].as_array().unwrap().iter())
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert_eq!((q[0], q[1]), (0.0, 0.0), "{o}");
        assert!((q[2] * q[2] + q[3] * q[3] - 1.0).abs() < 1e-9, "{o}");
    }
}

/// The SDK's goal: the robot had not been there before it was sent, and then drove
/// there (the SDK's /odom and the recorded pose of the simulation say so).
fn check_goal(report: &serde_json::Value, record: &Path, text: &str) {
    let goal: Vec<f64> = (report["goal"].as_array().expect(text).iter())
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert!(report["goal_sent"].as_u64().unwrap() >= 1, "{text}");
    assert_eq!(
        report["reached"], true,
        "the robot did not reach the goal: {text}"
    );
    let away = |p: &serde_json::Value| {
        (p[0].as_f64().unwrap() - goal[0]).hypot(p[1].as_f64().unwrap() - goal[1])
    };
    let odoms = report["odoms"].as_array().unwrap();
    let before = report["goal_after"].as_u64().unwrap() as usize;
    // When the goal was set, the robot was 1.2 m from it.
    assert!(
        (away(&odoms[before - 1]["position"]) - 1.2).abs() < 1e-9,
        "{text}"
    );
    let closest = odoms[before..].iter().map(|o| away(&o["position"]));
    assert!(closest.fold(f64::INFINITY, f64::min) < 0.15, "{text}");
    let poses = recorded_json(record, "fragile_bot/main/simulation/main_simulation/pose");
    let near = poses
        .iter()
        .any(|p| away(&serde_json::json!([p["x"], p["y"]])) < 0.15);
    assert!(near, "the recorded pose never came near the goal {goal:?}");
}

/// Every /tf message: the one transform odom → base_link, at the pose the odometry of
/// the same stamp gives (the SDK's subscription is on the key of rosbags' Jazzy hash).
fn check_tf(report: &serde_json::Value, text: &str) {
    let tfs = report["tfs"].as_array().unwrap();
    assert!(tfs.len() >= 10, "too few /tf messages: {text}");
    let odoms = report["odoms"].as_array().unwrap();
    let mut compared = 0;
    for tf in tfs {
        let [t] = &tf.as_array().unwrap()[..] else {
            panic!("one transform: {tf}");
        };
        assert_eq!(t["frame_id"], "odom", "{t}");
        assert_eq!(t["child_frame_id"], "base_link", "{t}");
        if let Some(o) = odoms.iter().find(|o| o["stamp"] == t["stamp"]) {
            assert_eq!(t["translation"], o["position"], "{t} {o}");
            assert_eq!(t["rotation"], o["orientation"], "{t} {o}");
            compared += 1;
        }
    }
    assert!(compared >= 10, "{text}");
}
