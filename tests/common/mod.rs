//! What the CLI test files share: running the built `ferroc` and scratch folders.
#![allow(dead_code)]

pub mod inspected;
pub mod no_shm;
pub mod web;

use std::path::{Path, PathBuf};
use std::process::Command;

/// Where the demo models' loggers write during tests (their paths are relative to
/// the log folder): never into the checkout.
pub fn test_log_dir() -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join("logs")
}

/// Runs `ferroc` in the project root: (exit code, stdout, stderr).
pub fn ferroc(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_ferroc"))
        .args(args)
        .env("FERROC_LOG_DIR", test_log_dir())
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("ferroc runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// An empty folder of this name under cargo's scratch directory for tests.
pub fn tempdir(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `ferroc bundle MODEL -o OUT EXTRA…`: its exit code and standard error.
pub fn bundle(model: &Path, out: &Path, extra: &[&str]) -> (i32, String) {
    let mut args = vec![
        "bundle",
        model.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend(extra);
    let (code, _, stderr) = ferroc(&args);
    (code, stderr)
}

/// `ferroc bundle MODEL -o OUT`, which must succeed.
pub fn bundle_ok(model: &Path, out: &Path) {
    let (code, stderr) = bundle(model, out, &[]);
    assert_eq!(code, 0, "{stderr}");
}

/// Builds the bundle in `out` into this test's target folder (its dependencies are
/// this checkout's crates by path, built there already) and returns that folder; the
/// build must succeed without a warning from the generated code.
pub fn build_bundle(out: &Path) -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let target = exe.ancestors().nth(3).unwrap().to_path_buf();
    let build = Command::new(env!("CARGO"))
        .args(["build", "--offline", "--quiet", "--manifest-path"])
        .arg(out.join("Cargo.toml"))
        .env("CARGO_TARGET_DIR", &target)
        .env_remove("RUSTFLAGS")
        .output()
        .expect("cargo runs");
    let log = String::from_utf8_lossy(&build.stderr);
    assert!(build.status.success(), "{log}");
    assert!(!log.contains("warning"), "the generated code warns:\n{log}");
    target
}

/// The Python interpreter with `mcap` and `jsonschema` (FERROC_PYTHON, else the venv
/// `scripts/test` makes), or `None` after a visible skip.
pub fn python() -> Option<std::path::PathBuf> {
    ferroc_testkit::python(&["mcap", "jsonschema"])
}
pub mod lsp_client;

/// A tmpfs of `size` mounted on `dir` for as long as it lives; `None` after a visible
/// skip (ferroc_testkit) where mounting is refused (not root, no CAP_SYS_ADMIN).
pub struct SmallDisk(PathBuf);

impl SmallDisk {
    pub fn mount(dir: &Path, size: &str) -> Option<SmallDisk> {
        Self::mount_with(dir, &format!("size={size}"))
    }

    /// A tmpfs mounted with these options (`ro`: a read-only folder even for root).
    pub fn mount_with(dir: &Path, options: &str) -> Option<SmallDisk> {
        let mount = ferroc_testkit::command("mount")?;
        std::fs::create_dir_all(dir).unwrap();
        let mounted = Command::new(mount)
            .args(["-t", "tmpfs", "-o", options, "tmpfs"])
            .arg(dir)
            .output()
            .expect("mount runs");
        if mounted.status.success() {
            return Some(SmallDisk(dir.to_path_buf()));
        }
        let why = String::from_utf8_lossy(&mounted.stderr);
        ferroc_testkit::skip(&format!(
            "needs to mount a small tmpfs (as root): {}",
            why.trim()
        ));
        None
    }
}

impl Drop for SmallDisk {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(&self.0).status();
    }
}

/// A child process killed (and reaped) when the test ends, however it ends.
pub struct Killed(pub std::process::Child);

impl Drop for Killed {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// The Cargo.toml of a library crate outside ferroc's workspace: package `package`,
/// library `lib`, the runtime of this checkout by path, a workspace of its own.
pub fn write_library_toml(dir: &Path, package: &str, lib: &str) {
    let runtime = Path::new(env!("CARGO_MANIFEST_DIR")).join("runtime");
    std::fs::create_dir_all(dir.join("src")).unwrap();
    std::fs::write(
        dir.join("Cargo.toml"),
        format!(
            "[package]\nname = \"{package}\"\nversion = \"0.1.0\"\nedition = \"2021\"\n\n\
             [lib]\nname = \"{lib}\"\n\n[dependencies]\nferroc-runtime = {{ path = {:?} }}\n\n[workspace]\n",
            runtime.to_str().unwrap()
        ),
    )
    .unwrap();
}
