//! The Copper ring binaries run a short ring and report it; bad arguments are usage
//! errors. `timed_round` itself refuses a round in which the matrix did not pass all
//! five stages every cycle, so a successful run is also a correct one. No figure is
//! checked (`cargo test --release` in bench/peers; never part of ferroc's tests).

use std::process::Command;

fn run(bin: &str, args: &[&str]) -> (i32, String) {
    let out = Command::new(bin).args(args).output().expect("the binary runs");
    let text = String::from_utf8_lossy(&out.stdout).to_string()
        + &String::from_utf8_lossy(&out.stderr);
    (out.status.code().unwrap_or(-1), text)
}

#[test]
fn logging_off_ring_reports_one_result_line() {
    let (code, text) = run(
        env!("CARGO_BIN_EXE_copper_ring_quiet"),
        &["--cycles", "2000", "--rounds", "2"],
    );
    assert_eq!(code, 0, "{text}");
    let results: Vec<&str> = text.lines().filter(|l| l.starts_with("RESULT ")).collect();
    assert_eq!(results.len(), 1, "{text}");
    assert!(results[0].contains("variant=logging-off") && results[0].contains("cycles=2000"));
}

#[test]
fn default_logging_ring_writes_its_log_where_told_and_removes_it() {
    let dir = std::env::temp_dir().join(format!("copper-b2-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (code, text) = run(
        env!("CARGO_BIN_EXE_copper_ring_default"),
        &["--cycles", "1000", "--rounds", "1", "--log-dir", dir.to_str().unwrap()],
    );
    assert_eq!(code, 0, "{text}");
    assert!(text.contains("variant=default-logging"), "{text}");
    assert!(text.contains("log files"), "the round's log was written: {text}");
    let left = std::fs::read_dir(&dir).unwrap().count();
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(left, 0, "the logs were removed");
}

#[test]
fn a_bad_argument_is_a_usage_error() {
    let (code, text) = run(env!("CARGO_BIN_EXE_copper_ring_quiet"), &["--cycles", "many"]);
    assert_eq!(code, 2, "{text}");
    assert!(text.contains("not a whole number") && text.contains("help:"), "{text}");
}
