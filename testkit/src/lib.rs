//! What the tests need from outside Rust: the clients we did not write (Python's
//! `eclipse-zenoh` and `mcap`, npm's Foxglove client, playwright with Debian's
//! Chromium) and programs such as `xmllint` or Graphviz's `dot`.
//!
//! `scripts/test` installs all of them. A test asks here for what it needs; when a
//! piece is missing the test is skipped *visibly*: one line on the terminal (written
//! past libtest's output capture, so `cargo test` shows it), naming the test, what is
//! missing and the command that installs it, and one line in the skip log that
//! `scripts/test` prints at the end of its run. With `FERROC_REQUIRE_ALL=1` (CI sets
//! it) a missing piece fails the test instead: a run that proves interoperability
//! must not pass by skipping it.
#![forbid(unsafe_code)]

mod port;

pub use port::{free_address, free_port};

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// The command that installs everything the tests need.
pub const SETUP: &str = "scripts/test --setup-only";

/// The checkout's root (this crate lives in `testkit/`).
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("testkit/ has a parent")
        .to_path_buf()
}

/// A Python interpreter that imports every one of `modules`: `$FERROC_PYTHON`, else the
/// venv `scripts/test` makes (`target/ci-venv`). `None` after a visible skip.
pub fn python(modules: &[&str]) -> Option<PathBuf> {
    find_python(modules).map_or_else(|what| missing(&what), Some)
}

/// The `node_modules` folder holding every one of `packages`, with Node.js on PATH:
/// `$FERROC_NODE_MODULES`, else the folder `scripts/test` fills
/// (`target/ci-node/node_modules`). `None` after a visible skip.
pub fn node_modules(packages: &[&str]) -> Option<PathBuf> {
    find_command("node")
        .and_then(|_| find_node_modules(packages))
        .map_or_else(|what| missing(&what), Some)
}

/// The program `name` found on PATH (or, for an absolute path, that file).
/// `None` after a visible skip.
pub fn command(name: &str) -> Option<PathBuf> {
    find_command(name).map_or_else(|what| missing(&what), Some)
}

/// The interpreter, or what is missing.
fn find_python(modules: &[&str]) -> Result<PathBuf, String> {
    let set = std::env::var_os("FERROC_PYTHON").map(PathBuf::from);
    let python = set
        .clone()
        .unwrap_or_else(|| root().join("target/ci-venv/bin/python"));
    let import = format!("import {}", modules.join(", "));
    let ok = Command::new(&python)
        .args(["-c", &import])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if ok {
        return Ok(python);
    }
    let how = if set.is_some() {
        "FERROC_PYTHON ="
    } else {
        "tried"
    };
    Err(format!(
        "a Python that can `{import}` ({how} {})",
        python.display()
    ))
}

/// The node_modules folder, or what is missing.
fn find_node_modules(packages: &[&str]) -> Result<PathBuf, String> {
    let dir = std::env::var_os("FERROC_NODE_MODULES")
        .map(PathBuf::from)
        .unwrap_or_else(|| root().join("target/ci-node/node_modules"));
    let absent: Vec<&str> = packages
        .iter()
        .copied()
        .filter(|p| !dir.join(p).join("package.json").is_file())
        .collect();
    if absent.is_empty() {
        return Ok(dir);
    }
    Err(format!(
        "the npm package(s) {} in {}",
        absent.join(", "),
        dir.display()
    ))
}

/// The program, or what is missing.
fn find_command(name: &str) -> Result<PathBuf, String> {
    let found = if Path::new(name).is_absolute() {
        Path::new(name).is_file().then(|| PathBuf::from(name))
    } else {
        std::env::var_os("PATH").and_then(|path| {
            std::env::split_paths(&path)
                .map(|dir| dir.join(name))
                .find(|p| p.is_file())
        })
    };
    found.ok_or_else(|| format!("the program `{name}` on PATH"))
}

/// Skips the calling test because `why` (something this machine cannot do, such as
/// making network namespaces without privileges), visibly and in the skip log; under
/// `FERROC_REQUIRE_ALL=1` it fails instead.
pub fn skip(why: &str) {
    report(why, "");
}

/// Reports `what` as missing and returns `None`, or panics under FERROC_REQUIRE_ALL.
fn missing<T>(what: &str) -> Option<T> {
    report(
        &format!("needs {what}"),
        &format!("; `{SETUP}` installs what is missing"),
    );
    None
}

fn report(why: &str, fix: &str) {
    let test = current_test();
    if required() {
        panic!("{test}: {why}{fix} (FERROC_REQUIRE_ALL=1 turns every skip into a failure)");
    }
    let line = format!("SKIPPED {test}: {why}{fix}\n");
    // Past libtest's capture (it only captures print!/eprint!), so a passing run shows it.
    let _ = std::io::stderr().lock().write_all(line.as_bytes());
    if let Some(log) = std::env::var_os("FERROC_SKIP_LOG") {
        let _ = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(log)
            .and_then(|mut f| f.write_all(line.as_bytes()));
    }
}

fn required() -> bool {
    std::env::var("FERROC_REQUIRE_ALL").is_ok_and(|v| v == "1")
}

/// The running test's name: libtest names each test's thread after the test.
fn current_test() -> String {
    let thread = std::thread::current();
    let name = thread.name().unwrap_or("a test");
    let binary = std::env::args()
        .next()
        .and_then(|a| {
            Path::new(&a)
                .file_name()
                .map(|f| f.to_string_lossy().into_owned())
        })
        .map(|f| f.rsplit_once('-').map_or(f.clone(), |(n, _)| n.to_owned()))
        .unwrap_or_default();
    if name == "main" {
        binary
    } else {
        format!("{binary}::{name}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_program_on_path_is_found_and_a_missing_one_is_not() {
        assert!(find_command("sh").is_ok_and(|p| p.ends_with("sh")));
        let missing = find_command("ferroc-no-such-program-7f3a").unwrap_err();
        assert_eq!(missing, "the program `ferroc-no-such-program-7f3a` on PATH");
        assert!(find_command("/no/such/file").is_err());
    }

    #[test]
    fn a_python_without_the_module_is_refused_naming_the_import() {
        let missing = find_python(&["ferroc_no_such_module_7f3a", "json"]).unwrap_err();
        assert!(
            missing.starts_with("a Python that can `import ferroc_no_such_module_7f3a, json`"),
            "{missing}"
        );
    }

    #[test]
    fn absent_npm_packages_are_named() {
        let missing = find_node_modules(&["ferroc-no-such-package-7f3a"]).unwrap_err();
        assert!(
            missing.starts_with("the npm package(s) ferroc-no-such-package-7f3a in "),
            "{missing}"
        );
    }

    #[test]
    fn the_test_is_named_by_its_binary_and_function() {
        let name = current_test();
        assert!(
            name.ends_with("the_test_is_named_by_its_binary_and_function"),
            "{name}"
        );
        assert!(name.starts_with("ferroc_testkit"), "{name}");
    }
}
