//! A ROS 2 service called, or offered, under another type hash (issue 29, "Bad input";
//! docs/ros2.md "On the wire"): zenoh-ros2-sdk (`tests/ros2/sdk_hash_peer.py`) given
//! another hash of std_srvs/srv/SetBool than ours, as a node built from a changed
//! SetBool.srv would have.
//!
//! The key of the call differs, so the module's service never sees it: the run reports
//! it (throttled, naming the service and both hashes, with a `help:`) and answers it
//! with an error reply that says the same (rmw_zenoh's client logs it, the SDK's fails
//! the call with it). Calls with the right hash, and calls of a second service whose
//! name begins with the first's, are answered and not reported. A module's client
//! whose server announces another hash reports that server.

use super::*;

const SWITCH_TWO: &str = "tests/ros2/switch_two.xml";
const HASH_REPORT: &str = "was sent with another type hash";

/// Runs `model` for 20 s listening on a free port beside `sdk_hash_peer.py MODE`: the
/// peer's JSON report and text, and the run's standard output.
fn beside_hash_peer(
    python: &Path,
    name: &str,
    model: &str,
    mode: &str,
) -> (serde_json::Value, String, String) {
    let dir = tempdir(name);
    build_runner_of(model, &dir);
    let port = free_port();
    let config = listening_config(&dir, port);
    let mut peer = Command::new(python);
    peer.arg(root().join("tests/ros2/sdk_hash_peer.py"))
        .args([mode, &port.to_string()])
        .arg(root().join("ros2/interfaces"))
        .arg("15")
        .env(
            "ZENOH_CONFIG_OVERRIDE",
            "listen/endpoints=[\"tcp/127.0.0.1:0\"]",
        );
    let Beside {
        report, text, out, ..
    } = both(peer, run_model(model, &config, &["--for", "20s"]));
    (report, text, out)
}

#[test]
fn a_call_under_another_type_hash_is_refused_reported_and_told_to_the_caller() {
    let Some(python) = ferroc_testkit::python(&["zenoh", "zenoh_ros2_sdk"]) else {
        return;
    };
    let (report, text, out) = beside_hash_peer(&python, "ros2_service_hash", SWITCH_TWO, "client");
    let theirs = report["wrong_key"]
        .as_str()
        .unwrap()
        .rsplit('/')
        .next()
        .unwrap();
    assert_eq!(theirs, format!("RIHS01_{}", "5a".repeat(32)), "{text}");

    // Silent: both services answered with the right hash, before and after.
    let answered = |what: &str| {
        let answers = report[what].as_array().unwrap();
        answers.len() == 2 && answers.iter().all(|a| a["success"] == true)
    };
    assert!(answered("before") && answered("after"), "{text}");

    // Fires: the caller is told, by the SDK's client and by a raw rmw_zenoh-like call.
    assert!(report["wrong_answer"].is_null(), "{text}");
    let told = |t: &str| t.contains("another type hash") && t.contains(theirs);
    let logged = report["sdk_logged"].as_array().unwrap();
    assert!(logged.iter().any(|l| told(l.as_str().unwrap())), "{text}");
    let errors = report["raw_errors"].as_array().unwrap();
    assert_eq!(
        (errors.len(), report["raw_oks"].as_u64()),
        (1, Some(0)),
        "{text}"
    );
    assert!(
        errors[0].as_str().unwrap().starts_with(
            "the ROS 2 service `/switch_bot/set_enabled` refused the request: it was sent \
             with another type hash, RIHS01_5a5a"
        ),
        "{text}"
    );

    // The run reports it once per kind (two wrong calls: one line), naming the service
    // and both hashes, with a help; never the spare service.
    let lines: Vec<&str> = out.lines().filter(|l| l.contains(HASH_REPORT)).collect();
    assert_eq!(lines.len(), 1, "{out}");
    let line = lines[0];
    assert!(
        line.starts_with(&format!(
            "warning: a request to the ROS 2 service `/switch_bot/set_enabled` was refused: \
             it was sent with another type hash, {theirs} (ours: RIHS01_"
        )),
        "{line}"
    );
    assert!(
        line.ends_with(
            "); help: the client's definition of `std_srvs/srv/SetBool` differs from ours, \
             give both sides the same one"
        ),
        "{line}"
    );
    assert!(!out.contains("/spare`"), "{out}");
}

#[test]
fn a_server_announcing_another_type_hash_is_reported_by_the_module_s_client() {
    let Some(python) = ferroc_testkit::python(&["zenoh_ros2_sdk"]) else {
        return;
    };
    let (report, text, out) = beside_hash_peer(&python, "ros2_server_hash", ASKER, "server");
    // Our calls never reach it (its key differs).
    assert_eq!(report["requests"], serde_json::json!([]), "{text}");
    let lines: Vec<&str> = (out.lines())
        .filter(|l| l.contains("announces another type hash"))
        .collect();
    assert_eq!(lines.len(), 1, "{out}");
    assert!(
        lines[0].starts_with(&format!(
            "warning: a server of the ROS 2 service `/switch_bot/set_enabled` announces \
             another type hash, RIHS01_{} (ours: RIHS01_",
            "5a".repeat(32)
        )),
        "{}",
        lines[0]
    );
    assert!(lines[0].contains("help: the server's definition of `std_srvs/srv/SetBool`"));
}
