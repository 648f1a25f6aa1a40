//! `ferroc run --inspect` and `ferroc inspect` with real Zenoh sessions on loopback:
//! values read, a parameter changed with the token (and its effect seen in the next
//! values), refused without it or with a value that does not check, and malformed
//! requests answered with errors while the program runs on.

mod common;

use common::ferroc;
use common::inspected::{free_port, start, Running};
use std::time::{Duration, Instant};

fn inspect(r: &Running, args: &[&str]) -> (i32, String, String) {
    let mut all = vec!["inspect", "--connect", r.address.as_str()];
    all.extend_from_slice(args);
    ferroc(&all)
}

/// `--get PATH --json`'s value field.
fn get(r: &Running, path: &str) -> serde_json::Value {
    let (code, out, err) = inspect(r, &["--get", path, "--json"]);
    assert_eq!(code, 0, "{err}");
    let answer: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    answer["value"].clone()
}

/// Asks until `path` has `want` (the change is applied at the module's next cycle).
fn eventually(r: &Running, path: &str, want: serde_json::Value) {
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        let got = get(r, path);
        if got == want {
            return;
        }
        assert!(
            Instant::now() < deadline,
            "{path} stayed {got}, wanted {want}"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
}

#[test]
fn values_are_read_and_a_checked_parameter_change_needs_the_token() {
    let r = start("tests/fixtures/inspect.xml");
    eventually(&r, "robot/main/scaled/output", serde_json::json!(8.0));
    // An input shows its writer's value.
    let (code, out, err) = inspect(&r, &["--get", "robot/main/scaled/input"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(out.trim(), "robot/main/speed/value = 4.0");
    let (code, out, _) = inspect(&r, &["--get", "robot/main/scaled/factor"]);
    assert_eq!(
        (code, out.trim()),
        (0, "robot/main/scaled/factor = 2 (f64)")
    );

    // No token, a wrong token, a value that does not check: refused, nothing changes.
    let (code, _, err) = inspect(&r, &["--set", "robot/main/scaled/factor=5"]);
    assert_eq!(code, 2, "clap requires --token: {err}");
    let wrong = "0".repeat(32);
    let (code, _, err) = inspect(
        &r,
        &["--set", "robot/main/scaled/factor=5", "--token", &wrong],
    );
    assert_eq!(code, 1);
    assert!(err.contains("not authorised"), "{err}");
    for (value, why) in [("abc", "is not a number"), ("5 m", "has no unit")] {
        let set = format!("robot/main/scaled/factor={value}");
        let (code, _, err) = inspect(&r, &["--set", &set, "--token", &r.token]);
        assert_eq!(code, 1, "{value}");
        assert!(
            err.contains(why) && err.contains("keeps its value 2"),
            "{value}: {err}"
        );
    }
    let (code, _, err) = inspect(
        &r,
        &[
            "--set",
            "robot/main/player_rate/value=1.5",
            "--token",
            &r.token,
        ],
    );
    assert_eq!(code, 1);
    assert!(
        err.contains("outside the allowed range"),
        "an activity is at most 1: {err}"
    );
    assert_eq!(get(&r, "robot/main/scaled/output"), serde_json::json!(8.0));
    assert_eq!(get(&r, "robot/main/scaled/factor"), serde_json::json!("2"));

    // With the token: applied, and the next values show it.
    let (code, out, err) = inspect(
        &r,
        &["--set", "robot/main/scaled/factor=5", "--token", &r.token],
    );
    assert_eq!(
        (code, out.trim()),
        (0, "robot/main/scaled/factor = 5 (f64)"),
        "{err}"
    );
    eventually(&r, "robot/main/scaled/output", serde_json::json!(20.0));
    let note = r.stderr.recv_timeout(Duration::from_secs(10)).unwrap();
    assert!(
        note.contains("refused a change with a wrong token"),
        "{note}"
    );
}

#[test]
fn the_nav_behaviours_run_is_inspected_and_a_speed_limit_takes_effect() {
    let r = start("models/nav_behaviours.xml");
    let (code, out, err) = inspect(&r, &["--list"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("application nav_behaviours, part robot"),
        "{out}"
    );
    assert!(
        out.contains("module robot/control/go_to_goal : nav_behaviours.GoToGoal (behaviour) at models/nav_behaviours.xml:"),
        "{out}"
    );
    assert!(
        out.contains("param max_speed = 0.5 m/s (f64, 0..=2)"),
        "{out}"
    );
    assert!(
        out.contains("behaviour robot/control/avoid: activity "),
        "{out}"
    );
    assert!(out.contains("container robot/control: "), "{out}");
    // No part is a ROS 2 node: no port says it is a topic (tests/inspect_ros2.rs).
    assert!(!out.contains("ROS 2"), "{out}");
    // A library struct registered with its serde form (the manifest says serde="true"):
    // a JSON object with the struct's fields, not its Debug text.
    let pose = get(&r, "robot/control/sim/pose");
    for field in ["x", "y", "theta"] {
        assert!(pose[field].is_f64(), "{field} in {pose}");
    }
    // A unit of another dimension is refused; a unit of the same one is converted.
    let (code, _, err) = inspect(
        &r,
        &[
            "--set",
            "robot/control/go_to_goal/max_speed=3 kg",
            "--token",
            &r.token,
        ],
    );
    assert_eq!(code, 1);
    assert!(err.contains("measures"), "{err}");
    let (code, out, err) = inspect(
        &r,
        &[
            "--set",
            "robot/control/go_to_goal/max_speed=5 cm/s",
            "--token",
            &r.token,
        ],
    );
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("max_speed = 0.05 m/s"), "{out}");
    // The next values obey the new limit: watched, bounded by --count.
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        let (code, out, err) = inspect(
            &r,
            &[
                "--watch",
                "robot/control/go_to_goal/linear",
                "--count",
                "5",
                "--every",
                "20ms",
                "--json",
            ],
        );
        assert_eq!(code, 0, "{err}");
        let speeds: Vec<f64> = out
            .lines()
            .map(|l| {
                serde_json::from_str::<serde_json::Value>(l).unwrap()["value"]
                    .as_f64()
                    .unwrap()
            })
            .collect();
        assert_eq!(speeds.len(), 5, "{out}");
        if speeds.iter().all(|s| s.abs() <= 0.05 + 1e-9) {
            break;
        }
        assert!(
            Instant::now() < deadline,
            "still faster than 5 cm/s: {speeds:?}"
        );
    }
}

#[test]
fn a_non_local_address_needs_the_public_flag_and_a_served_run_ends_cleanly() {
    let (code, _, err) = ferroc(&[
        "run",
        "tests/fixtures/inspect.xml",
        "--cycles",
        "1",
        "--inspect",
        "0.0.0.0:47900",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("not a loopback address") && err.contains("--inspect-public"),
        "{err}"
    );
    // Serving does not keep a finished run alive.
    let address = format!("127.0.0.1:{}", free_port());
    let (code, _, err) = ferroc(&[
        "run",
        "tests/fixtures/inspect.xml",
        "--lockstep",
        "--cycles",
        "5",
        "-q",
        "--inspect",
        &address,
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains(&format!(
            "serving ferroc/inspected/inspect/** on tcp/{address}; token for changes: "
        )),
        "{err}"
    );
}

/// The lines of the program's standard error up to one containing `marker`.
fn lines_until(r: &Running, marker: &str) -> Vec<String> {
    let deadline = Instant::now() + Duration::from_secs(60);
    let mut seen = Vec::new();
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        let line = r
            .stderr
            .recv_timeout(left)
            .unwrap_or_else(|_| panic!("no line with `{marker}`; saw:\n{}", seen.join("\n")));
        let done = line.contains(marker);
        seen.push(line);
        if done {
            return seen;
        }
    }
}

/// Issue 27, item 4: every wrong token wrote a line (2,000 tries, 2,000 lines). They are
/// throttled as other repeated warnings are: the 1st, 10th, 100th… with the count.
/// Failed before the fix (200 lines).
#[test]
fn wrong_tokens_are_reported_throttled() {
    let r = start("tests/fixtures/inspect.xml");
    let client = ferroc_inspect::client::Client::connect(std::slice::from_ref(&r.address)).unwrap();
    let wrong = "0".repeat(32);
    for _ in 0..200 {
        let e = client
            .set::<serde_json::Value>("*", "robot/main/scaled/factor", "3", &wrong)
            .unwrap_err();
        assert!(e.contains("not authorised"), "{e}");
    }
    // A change with the right token: its line marks the end of what the tries wrote.
    client
        .set::<serde_json::Value>("*", "robot/main/scaled/factor", "3", &r.token)
        .unwrap();
    let lines = lines_until(&r, "set to 3");
    let refused: Vec<&String> = lines.iter().filter(|l| l.contains("wrong token")).collect();
    assert_eq!(refused.len(), 3, "{lines:#?}");
    assert!(refused[1].contains("repeated: 10 times"), "{refused:?}");
    assert!(refused[2].contains("repeated: 100 times"), "{refused:?}");
}

/// The peak resident memory of process `pid` (VmHWM), in bytes.
fn peak_memory(pid: u32) -> u64 {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap();
    let line = status.lines().find(|l| l.starts_with("VmHWM:")).unwrap();
    let kib: u64 = line.split_whitespace().nth(1).unwrap().parse().unwrap();
    kib * 1024
}

/// Issue 27, item 2: a 1 GB request, sent without a token, was read whole before its
/// size was checked (54 MB → 2.16 GB). The inspection session takes no message over
/// 256 KiB from the network, and a payload over 64 KiB is refused before it is copied
/// into one buffer. Failed before the fix (the program's peak memory grew by more than
/// the 200 MB sent).
#[test]
fn a_huge_request_costs_the_program_no_memory() {
    let r = start("tests/fixtures/inspect.xml");
    eventually(&r, "robot/main/scaled/output", serde_json::json!(8.0));
    let before = peak_memory(r.child.id());
    let client = ferroc_inspect::client::Client::connect(std::slice::from_ref(&r.address)).unwrap();
    let key = "ferroc/*/inspect/robot/edit";
    // Dropped by the session: the program never sees it (the query times out).
    let huge = vec![b'['; 200 << 20];
    let answers = client
        .ask_within(key, Some(huge), Duration::from_secs(2))
        .unwrap();
    assert!(
        (answers.iter()).all(|a| a
            .result
            .as_ref()
            .is_err_and(|e| e.contains("not answered in time"))),
        "{answers:?}"
    );
    // Taken by the session, refused by its size.
    let large = vec![b'['; 100 << 10];
    let answers = client.ask(key, Some(large)).unwrap();
    let e = answers[0].result.as_ref().unwrap_err();
    assert!(e.contains("a request is at most 65536"), "{e}");
    // The program serves on, having grown by far less than what was sent.
    assert_eq!(get(&r, "robot/main/scaled/output"), serde_json::json!(8.0));
    let grown = peak_memory(r.child.id()).saturating_sub(before);
    eprintln!("peak memory of the program: {before} bytes before, grown by {grown}");
    assert!(grown < 50 << 20, "the program grew by {grown} bytes");
}
