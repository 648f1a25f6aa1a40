//! Proof against an implementation we did not write: Python `rosbags` (PyPI) reads the
//! `ros2msg` schema text ferroc writes into MCAP recordings (`mcap_schema`) for every
//! shipped message type, finds every dependency in the text itself, and computes the
//! RIHS01 hash ferroc computes from its own definitions. (tests/mcap_schema_check.py is
//! its side.)

use std::io::Write;
use std::process::{Command, Stdio};

use ferroc_ros2::def::TypeName;
use ferroc_ros2::{hash, mcap_schema, Registry};
use serde_json::{json, Value as Json};

#[test]
fn rosbags_reads_every_shipped_message_s_schema_text_to_the_same_type() {
    let Some(python) = ferroc_testkit::python(&["rosbags"]) else {
        return;
    };
    let registry = Registry::shipped();
    let names: Vec<TypeName> = (registry.messages())
        .map(|m| m.name.clone())
        .filter(|n| n.kind == "msg")
        .collect();
    let mut schemas = serde_json::Map::new();
    for name in &names {
        let text = mcap_schema::schema_text(&registry, name).expect("a shipped type");
        schemas.insert(name.to_string(), json!(text));
    }
    let answer = run(&python, &json!({ "schemas": schemas }));
    for name in &names {
        let ours = hash::rihs01(&registry, name).expect("hashes");
        let theirs = &answer["hashes"][name.to_string()];
        // [rosbags as is, with rosidl's char → uint8]: the second is rosidl's hash.
        assert_eq!(
            theirs[1],
            json!(ours),
            "RIHS01 of {name} read from its schema text"
        );
    }
    let odometry = &answer["hashes"]["nav_msgs/msg/Odometry"][2];
    assert!(
        odometry
            .as_array()
            .unwrap()
            .contains(&json!("builtin_interfaces/msg/Time")),
        "a dependency two levels down is read from the text: {odometry}"
    );
    assert!(names.len() > 80, "every shipped message ({})", names.len());
}

fn run(python: &std::path::Path, request: &Json) -> Json {
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/mcap_schema_check.py");
    let mut child = Command::new(python)
        .arg(script)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("python starts");
    let mut stdin = child.stdin.take().expect("stdin");
    stdin
        .write_all(request.to_string().as_bytes())
        .expect("request written");
    drop(stdin);
    let out = child.wait_with_output().expect("python ends");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("a JSON answer")
}
