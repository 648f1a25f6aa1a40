//! A report that cannot be written is never lost silently and never panics: a reader
//! that closed the pipe ends the output quietly (the exit code stands), a full disk is
//! exit code 2 with a message.

use std::process::{Command, Stdio};

/// Runs ferroc with standard output as given: (exit code, stderr).
fn run_into(args: &[&str], stdout: Stdio) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_ferroc"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdout(stdout)
        .stderr(Stdio::piped())
        .output()
        .expect("ferroc runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A stream whose reader is gone before ferroc writes: every write fails with EPIPE
/// (a socket pair behaves as a pipe here, and needs no newer std than the MSRV).
fn closed_pipe() -> Stdio {
    let (writer, reader) = std::os::unix::net::UnixStream::pair().unwrap();
    drop(reader);
    std::os::fd::OwnedFd::from(writer).into()
}

fn full_disk() -> Stdio {
    std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap()
        .into()
}

const COMMANDS: &[&[&str]] = &[
    &["explain", "--list"],
    &["explain", "T102"],
    &["types", "list"],
    &["schedule", "models/crash_course.xml"],
    &["check", "models/crash_course.xml", "--format", "json"],
    &["check", "models/crash_course.xml", "--format", "sarif"],
    &["check", "models/crash_course.xml"],
    &["graph", "models/crash_course.xml"],
    // Issue 27 item 9: help and version to /dev/full exited 0 (these failed so before
    // the fix); `new model -` writes the model to standard output.
    &["--help"],
    &["--version"],
    &["check", "--help"],
    &["new", "model", "-"],
];

#[test]
fn a_closed_pipe_ends_the_output_quietly() {
    for args in COMMANDS {
        let (code, err) = run_into(args, closed_pipe());
        assert_eq!(code, 0, "{args:?}: {err}");
        assert!(err.is_empty(), "{args:?} says nothing: {err}");
    }
}

#[test]
fn a_full_disk_is_an_error_with_exit_code_2() {
    for args in COMMANDS {
        let (code, err) = run_into(args, full_disk());
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(
            err.contains("error: cannot write to standard output: No space left on device"),
            "{args:?}: {err}"
        );
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
}

/// Commands whose messages go to standard error (a run's status and stop lines, a
/// check's tool error, a bad option).
const TO_STDERR: &[(&[&str], i32)] = &[
    (
        &[
            "run",
            "models/rescue_robot.xml",
            "--lockstep",
            "--cycles",
            "3",
        ],
        0,
    ),
    (&["check", "models/no-such-model.xml"], 2),
    (&["check", "--no-such-option"], 2),
];

/// Standard error closed or full: the messages are lost, but nothing panics and the
/// exit code stands (std's `eprintln!` panicked here with exit code 101).
#[test]
fn an_unwritable_standard_error_changes_nothing_but_the_messages() {
    for (args, expected) in TO_STDERR {
        for (what, stderr) in [("closed pipe", closed_pipe()), ("full disk", full_disk())] {
            let out = Command::new(env!("CARGO_BIN_EXE_ferroc"))
                .args(*args)
                .current_dir(env!("CARGO_MANIFEST_DIR"))
                .stdout(Stdio::piped())
                .stderr(stderr)
                .output()
                .expect("ferroc runs");
            assert_eq!(
                out.status.code(),
                Some(*expected),
                "{args:?} with stderr a {what}"
            );
        }
    }
}
