//! A recording while `ferroc run` runs freely: stopped by Ctrl-C (SIGINT) it is
//! finished cleanly; killed (SIGKILL, a crash) it stays readable up to the last chunk
//! written; `ferroc log info` says which. Nothing here depends on how fast the machine
//! is: the tests wait (bounded) for the file to have data, then signal.

mod common;
use common::{ferroc, tempdir};
use ferroc_std::recording::Recording;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

fn start(dir: &Path) -> Child {
    Command::new(env!("CARGO_BIN_EXE_ferroc"))
        .args(["run", "models/crash_course_logged.xml", "-q", "--log-dir"])
        .arg(dir)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("ferroc runs")
}

/// Waits (at most a minute) until the recording holds at least one message.
fn wait_for_messages(file: &Path) {
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        if Recording::read(file).is_ok_and(|r| !r.messages.is_empty()) {
            return;
        }
        assert!(
            Instant::now() < deadline,
            "no message reached {}",
            file.display()
        );
        std::thread::sleep(Duration::from_millis(100));
    }
}

fn signal(child: &Child, name: &str) {
    let ok = Command::new("kill")
        .args([name, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(ok.success());
}

#[test]
fn ctrl_c_finishes_the_recording_cleanly() {
    let dir = tempdir("recording_sigint");
    let file = dir.join("logs/crash_course.mcap");
    let mut child = start(&dir);
    wait_for_messages(&file);
    signal(&child, "-INT");
    let status = child.wait().unwrap();
    assert!(status.success(), "{status:?}");
    let rec = Recording::read(&file).unwrap();
    assert!(rec.finished, "summary and footer written on stop");
    assert_eq!(rec.damaged, None);
    let (code, out, _) = ferroc(&["log", "info", file.to_str().unwrap()]);
    assert_eq!(code, 0);
    assert!(out.contains(": finished"), "{out}");
}

#[test]
fn a_crash_loses_at_most_the_chunk_under_way() {
    let dir = tempdir("recording_sigkill");
    let file = dir.join("logs/crash_course.mcap");
    let mut child = start(&dir);
    wait_for_messages(&file);
    let seen = Recording::read(&file).unwrap().messages.len();
    signal(&child, "-KILL");
    let _ = child.wait();
    // Everything flushed before the kill is still there, the end is not.
    let rec = Recording::read(&file).unwrap();
    assert!(
        rec.messages.len() >= seen,
        "{} < {seen}",
        rec.messages.len()
    );
    assert!(!rec.finished);
    let (code, out, _) = ferroc(&["log", "info", file.to_str().unwrap()]);
    assert_eq!(code, 0, "{out}");
    assert!(
        out.contains("not finished") || out.contains("cut off"),
        "{out}"
    );
    // Cut in the middle of a chunk: read up to the cut, and said so.
    let bytes = std::fs::read(&file).unwrap();
    let cut = dir.join("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() - 7]).unwrap();
    let (code, out, err) = ferroc(&["log", "info", cut.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("cut off") || out.contains("not finished"),
        "{out}"
    );
}
