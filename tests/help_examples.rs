//! Every example in every `--help` runs as printed: the test walks `ferroc help` through
//! every command, takes the lines of each `Example:`/`Examples:` block and runs the
//! `ferroc` ones with `sh` (so `> file` and `&` work as in a shell) in a scratch folder
//! that holds the checkout's `models/`, `components/` and `schemas/` (outputs such as
//! `dist/` or `run.mcap` land there, not in the checkout). Each must exit 0.
//!
//! What a block needs around it, the test does as a user would: a block that starts a
//! program in the background (`… --inspect &`) waits until it answers and is stopped at
//! the end, `TOKEN` is the token that program printed, a run without `--for` or
//! `--cycles` gets Ctrl-C (SIGINT) after a few seconds, FINROC examples run in a copy of
//! the crash-course checkout. Lines that are not `ferroc` (`cargo build`, a bundle's
//! program) are cargo's and the bundle's, run by tests/bundle.rs.

mod common;
use common::tempdir;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// `ferroc help ARGS…`'s text.
fn help(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_ferroc"))
        .arg("help")
        .args(args)
        .output()
        .unwrap();
    assert!(out.status.success(), "ferroc help {args:?}");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The subcommands a help text lists (`Commands:` block), without `help`.
fn subcommands(text: &str) -> Vec<String> {
    let Some(at) = text.find("\nCommands:\n") else {
        return Vec::new();
    };
    text[at + 11..]
        .lines()
        .take_while(|l| l.starts_with("  "))
        // A wrapped description continues deeper in; a command stands at two spaces.
        .filter(|l| !l[2..].starts_with(' '))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .map(str::to_string)
        .collect()
}

/// Every command path (`["types", "export"]`) with its examples.
fn examples() -> Vec<(Vec<String>, Vec<String>)> {
    let mut out = Vec::new();
    let mut todo = vec![Vec::<String>::new()];
    while let Some(path) = todo.pop() {
        let args: Vec<&str> = path.iter().map(String::as_str).collect();
        let text = help(&args);
        for sub in subcommands(&text) {
            let mut p = path.clone();
            p.push(sub);
            todo.push(p);
        }
        let mut lines = Vec::new();
        let mut inside = false;
        for line in text.lines() {
            if line.starts_with("Example") && line.ends_with(':') {
                inside = true;
            } else if inside && line.starts_with("  ") {
                lines.push(line.trim().to_string());
            } else {
                inside = false;
            }
        }
        if !lines.is_empty() {
            out.push((path, lines));
        }
    }
    out.sort();
    out
}

/// A folder with the checkout's models, manifests and schemas (symbolic links).
fn scratch(name: &str) -> PathBuf {
    let dir = tempdir(name);
    for d in ["models", "components", "schemas"] {
        std::os::unix::fs::symlink(root().join(d), dir.join(d)).unwrap();
    }
    dir
}

fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap().flatten() {
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_tree(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), target).unwrap();
        }
    }
}

fn shell(line: &str, dir: &Path) -> Command {
    let bin = Path::new(env!("CARGO_BIN_EXE_ferroc")).parent().unwrap();
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let mut cmd = Command::new("sh");
    cmd.args(["-c", line])
        .current_dir(dir)
        .env("PATH", path)
        // The runners of the models' libraries: the ones the other tests built.
        .env("CARGO_TARGET_DIR", root().join("target"))
        .env_remove("FERROC_LOG_DIR");
    cmd
}

/// Runs one example line; a run that would go on until Ctrl-C gets it after `after`.
fn run_line(line: &str, dir: &Path, token: &str) -> Result<(), String> {
    let line = line.replace("TOKEN", token);
    let endless =
        line.starts_with("ferroc run ") && !line.contains("--for") && !line.contains("--cycles");
    let mut child = shell(&format!("exec {line}"), dir)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    if endless {
        // Started, then stopped as a user stops it: a clean stop is exit 0.
        wait_started(&mut child);
        Command::new("kill")
            .args(["-INT", &child.id().to_string()])
            .status()
            .unwrap();
    }
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    let status = child.wait().unwrap();
    if status.success() {
        Ok(())
    } else {
        Err(format!("`{line}` in {}: {status}\n{err}", dir.display()))
    }
}

/// Lets the child run a few seconds (its runner is built by the other tests); returns
/// early if it exits by itself, which the caller then reports.
fn wait_started(child: &mut Child) {
    let start = Instant::now();
    while start.elapsed() < Duration::from_secs(5) {
        if child.try_wait().unwrap().is_some() {
            return;
        }
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// A block with `… &` lines: starts those, waits until `ferroc inspect --list` answers,
/// runs the rest with the printed token, then stops the background programs.
fn run_served(lines: &[String], dir: &Path) -> Vec<String> {
    let mut failures = Vec::new();
    let mut servers = Vec::new();
    let mut token = String::new();
    for line in lines.iter().filter(|l| l.ends_with('&')) {
        let line = line.trim_end_matches('&').trim();
        let mut child = shell(&format!("exec {line}"), dir)
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut stderr = child.stderr.take().unwrap();
        // The token line comes once the program serves (after a runner build, if any).
        let mut seen = String::new();
        let start = Instant::now();
        let mut buf = [0u8; 256];
        // The whole token line: a read may end inside it.
        let whole = |seen: &str| {
            seen.find("token for changes: ")
                .is_some_and(|at| seen[at..].contains('\n'))
        };
        while !whole(&seen) && start.elapsed() < Duration::from_secs(900) {
            match stderr.read(&mut buf) {
                Ok(0) | Err(_) => break,
                Ok(n) => seen.push_str(&String::from_utf8_lossy(&buf[..n])),
            }
        }
        if let Some(at) = seen.find("token for changes: ") {
            token = seen[at + 19..]
                .split_whitespace()
                .next()
                .unwrap_or("")
                .to_string();
        } else {
            failures.push(format!("`{line}` printed no token:\n{seen}"));
        }
        // Keep draining its stderr so it never blocks on a full pipe.
        std::thread::spawn(move || std::io::copy(&mut stderr, &mut std::io::sink()));
        servers.push(child);
    }
    for line in lines
        .iter()
        .filter(|l| !l.ends_with('&') && l.starts_with("ferroc "))
    {
        if let Err(e) = run_line(line, dir, &token) {
            failures.push(e);
        }
    }
    for mut s in servers {
        let _ = Command::new("kill")
            .args(["-INT", &s.id().to_string()])
            .status();
        let _ = s.wait();
    }
    failures
}

#[test]
fn every_help_example_runs_as_printed() {
    let all = examples();
    let names: Vec<String> = all.iter().map(|(p, _)| p.join(" ")).collect();
    // Every command that has examples is found (the walk reaches nested commands).
    for want in [
        "",
        "check",
        "run",
        "bundle",
        "log",
        "inspect",
        "import finroc",
        "export finroc",
        "types export",
    ] {
        let found = names.iter().any(|n| n == want)
            || (want.is_empty() && names.iter().any(String::is_empty));
        assert!(found, "no examples found for `ferroc {want}`: {names:?}");
    }
    let has_dot = ferroc_testkit::command("dot").is_some();
    let mut failures = Vec::new();
    let mut ran = 0;
    for (path, lines) in &all {
        let name = path.join("_");
        let dir = scratch(&format!("help_examples_{name}"));
        let finroc = path.first().is_some_and(|c| c == "import" || c == "export");
        let dir = if finroc {
            // In the checkout's folder, as the import example says; the export examples
            // export the model the import wrote and FINROC's round-trip file.
            let files = root().join("compiler/tests/finroc_files");
            copy_tree(&files.join("crash_course"), &dir);
            for f in ["type_conversion.finroc", "type_conversion_group.xml"] {
                std::fs::copy(files.join(f), dir.join(f)).unwrap();
            }
            if path[0] == "export" {
                let import = "ferroc import finroc CrashCourse.finroc -o crash_course.xml";
                run_line(import, &dir, "").unwrap();
            }
            dir
        } else {
            dir
        };
        if lines.iter().any(|l| l.ends_with('&')) {
            ran += lines.len();
            failures.extend(run_served(lines, &dir));
            continue;
        }
        for line in lines.iter().filter(|l| l.starts_with("ferroc ")) {
            if line.contains("--format svg") && !has_dot {
                continue; // the skip is said by the testkit
            }
            ran += 1;
            if let Err(e) = run_line(line, &dir, "") {
                failures.push(e);
            }
        }
    }
    assert!(ran >= 25, "only {ran} examples ran");
    assert!(
        failures.is_empty(),
        "{} example(s) failed:\n{}",
        failures.len(),
        failures.join("\n\n")
    );
}
