//! Recordings that must not lose or corrupt data (issue 27): nothing overwritten that
//! is not a recording of ours, log paths kept in the log folder, a full disk reported
//! in the summary and the exit code, corrupted files refused naming the chunk, and
//! memory bounded whatever a file's size.

mod common;
use common::{ferroc, tempdir};
use ferroc_std::recording::Recording;
use std::path::Path;
use std::process::Command;

/// A clock logged into `file` (the Logger's `file` parameter as written).
fn clock_logging_into(dir: &Path, file: &str) -> std::path::PathBuf {
    let model = dir.join("clock_logged.xml");
    let text = std::fs::read_to_string("tests/fixtures/clock_logged.xml").unwrap();
    std::fs::write(&model, text.replace(">clock.mcap<", &format!(">{file}<"))).unwrap();
    model
}

/// Issue 27 item 6: `ferroc run self.xml --record self.xml` replaced the model with
/// MCAP and exited 0 (this test failed so before the fix). A file that is not a
/// recording of ours is never overwritten without --force; one of ours is.
#[test]
fn record_never_replaces_a_file_that_is_not_a_recording_without_force() {
    let dir = tempdir("recording_no_overwrite");
    let victim = dir.join("notes.txt");
    std::fs::write(&victim, "precious").unwrap();
    let v = victim.to_str().unwrap();
    let args = [
        "run",
        "models/crash_course.xml",
        "--lockstep",
        "--for",
        "1s",
        "-q",
    ];
    let (code, _, err) = ferroc(&[&args[..], &["--record", v]].concat());
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("is not a ferroc recording: it is not replaced")
            && err.contains("help: name another file, or pass --force"),
        "{err}"
    );
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
    // --force replaces it; then it is a recording of ours, replaced without asking.
    let (code, _, err) = ferroc(&[&args[..], &["--record", v, "--force"]].concat());
    assert_eq!(code, 0, "{err}");
    assert!(Recording::read(&victim).unwrap().finished);
    let (code, _, err) = ferroc(&[&args[..], &["--record", v]].concat());
    assert_eq!(code, 0, "{err}");
    // An empty file holds nothing to lose.
    let empty = dir.join("empty.mcap");
    std::fs::write(&empty, "").unwrap();
    let (code, _, err) = ferroc(&[&args[..], &["--record", empty.to_str().unwrap()]].concat());
    assert_eq!(code, 0, "{err}");
}

/// Issue 27 item 6: a Logger's path from the model lies in the log folder (an
/// absolute path elsewhere was written; this test failed so before the fix), and it
/// does not replace a file there that is not a recording of ours.
#[test]
fn a_logger_writes_only_recordings_inside_the_log_folder() {
    let dir = tempdir("recording_logger_confined");
    let logs = dir.join("logs");
    std::fs::create_dir_all(&logs).unwrap();
    let outside = dir.join("outside.mcap");
    let run_model = |model: &Path, extra: &[&str]| {
        let mut args = vec!["run", model.to_str().unwrap(), "--lockstep", "--for", "1s"];
        args.extend_from_slice(&["-q", "--log-dir", logs.to_str().unwrap()]);
        args.extend_from_slice(extra);
        ferroc(&args)
    };
    let model = clock_logging_into(&dir, outside.to_str().unwrap());
    let (code, _, err) = run_model(&model, &[]);
    assert_ne!(code, 0, "{err}");
    assert!(err.contains("lies outside the log folder"), "{err}");
    assert!(
        err.contains("help: name the file relative to the log folder"),
        "{err}"
    );
    assert!(!outside.exists());
    // An absolute path into the log folder is fine.
    let inside = logs.join("inside.mcap");
    let model = clock_logging_into(&dir, inside.to_str().unwrap());
    let (code, _, err) = run_model(&model, &[]);
    assert_eq!(code, 0, "{err}");
    assert!(Recording::read(&inside).unwrap().finished);
    // A file there that is not a recording: refused when the logger is made, kept.
    std::fs::write(logs.join("clock.mcap"), "precious").unwrap();
    let model = clock_logging_into(&dir, "clock.mcap");
    let (code, _, err) = run_model(&model, &[]);
    assert_ne!(code, 0, "{err}");
    assert!(err.contains("is not a ferroc recording"), "{err}");
    assert_eq!(
        std::fs::read_to_string(logs.join("clock.mcap")).unwrap(),
        "precious"
    );
    let (code, _, err) = run_model(&model, &["--force"]);
    assert_eq!(code, 0, "{err}");
    assert!(Recording::read(&logs.join("clock.mcap")).unwrap().finished);
}

/// Issue 27 item 8: a Logger that fills its disk warned, but the run exited 0 with a
/// silent summary and the cause was "I/O error" (this test failed so before the fix).
/// Now the summary names the lost recordings, the cause is a full disk, exit code 3.
#[test]
fn a_full_disk_is_named_in_the_summary_and_the_exit_code() {
    let dir = tempdir("recording_full_disk");
    let full = dir.join("full");
    let Some(_disk) = common::SmallDisk::mount(&full, "32k") else {
        return;
    };
    let (code, out, err) = ferroc(&[
        "run",
        "models/crash_course_logged.xml",
        "--lockstep",
        "--for",
        "60s",
        "-q",
        "--log-dir",
        full.to_str().unwrap(),
    ]);
    assert_eq!(code, 3, "{out}\n{err}");
    let summary = err
        .split("data lost (exit code 3):")
        .nth(1)
        .unwrap_or_else(|| panic!("no losses in the summary: {err}"));
    assert!(
        summary.contains("ferroc_std.Logger `fragile_bot/main/")
            && summary.contains("`: cannot write the recording"),
        "{summary}"
    );
    assert!(summary.contains("logs/crash_course.mcap"), "{summary}");
    assert!(summary.contains("the disk is full"), "{summary}");
    assert!(!err.contains("I/O error"), "{err}");
    // What reached the disk before is still a readable recording.
    let rec = Recording::read(&full.join("logs/crash_course.mcap")).unwrap();
    assert!(!rec.finished);
}

/// A finished recording made in the test: one clock, `cycles` 40 ms steps.
fn clock_recording(dir: &Path) -> std::path::PathBuf {
    let (code, _, err) = ferroc(&[
        "run",
        "tests/fixtures/clock_logged.xml",
        "--lockstep",
        "--for",
        "2s",
        "-q",
        "--log-dir",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    dir.join("clock.mcap")
}

/// Issue 27 item 7: `log info` said "finished" and `log cat` printed the flipped
/// value of a bit-flipped file (this test failed so before the fix). Now both refuse
/// it naming the chunk; --ignore-checksums reads it and says it is corrupted.
#[test]
fn log_refuses_a_corrupted_recording_naming_the_chunk() {
    let dir = tempdir("recording_corrupted");
    let file = clock_recording(&dir);
    let mut bytes = std::fs::read(&file).unwrap();
    // The last byte of the first chunk's records (after the magic and header).
    let len = |at: usize| u64::from_le_bytes(bytes[at + 1..at + 9].try_into().unwrap()) as usize;
    // The first chunk: after the header and the records before it (ferroc.run metadata).
    let mut chunk = 8;
    while bytes[chunk] != 0x06 {
        chunk += 9 + len(chunk);
    }
    let at = chunk + 9 + len(chunk) - 1;
    bytes[at] ^= 0x02;
    std::fs::write(&file, &bytes).unwrap();
    let f = file.to_str().unwrap();
    let (code, out, err) = ferroc(&["log", "info", f]);
    assert_eq!(code, 2, "{out}");
    assert!(
        err.contains(&format!(
            "is corrupted: chunk 1 (the record at byte {chunk}) does not match its CRC"
        )),
        "{err}"
    );
    assert!(err.contains("help: "), "{err}");
    let (code, out, err) = ferroc(&["log", "cat", f, "--channel", "clocks/main/log/in/0"]);
    assert_eq!(code, 2, "{out}");
    assert!(err.contains("is corrupted: chunk 1"), "{err}");
    let (code, out, err) = ferroc(&["log", "info", f, "--ignore-checksums"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains(": corrupted: chunk 1 (the record at byte"),
        "{out}"
    );
}

/// Issue 27 item 12: a recording was read into memory whole before its size was
/// checked (a sparse 3 GiB file cost 4 GB of memory; this test failed so before the
/// fix: the reader ran out of its address space). Now memory follows the largest
/// record, not the file: `log info` reads a 3 GiB file within 1 GiB of address space.
#[test]
fn a_huge_sparse_recording_is_read_in_bounded_memory() {
    let dir = tempdir("recording_sparse");
    let file = clock_recording(&dir);
    let sparse = dir.join("sparse.mcap");
    std::fs::copy(&file, &sparse).unwrap();
    let f = std::fs::OpenOptions::new()
        .write(true)
        .open(&sparse)
        .unwrap();
    f.set_len(3 << 30).unwrap();
    // Zeros after the magic: no record at all.
    let zeros = dir.join("zeros.mcap");
    let z = std::fs::File::create(&zeros).unwrap();
    std::io::Write::write_all(&mut &z, b"\x89MCAP0\r\n").unwrap();
    z.set_len(3 << 30).unwrap();
    for (path, says) in [
        (&sparse, ": finished"),
        (&zeros, "opcode 0x00 is no MCAP record"),
    ] {
        let limited = format!(
            "ulimit -v 1048576 && exec {} log info {}",
            env!("CARGO_BIN_EXE_ferroc"),
            path.display()
        );
        let out = Command::new("sh").args(["-c", &limited]).output().unwrap();
        let (stdout, stderr) = (
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr),
        );
        assert_eq!(out.status.code(), Some(0), "{stdout}\n{stderr}");
        assert!(stdout.contains(says), "{stdout}");
    }
}
