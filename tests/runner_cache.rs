//! One build cache for the runners of every library: a second library compiles only its
//! own crate and a small `main`, the progress line says what is built and why, `ferroc
//! cache` shows and cleans it, and a cache that is read-only, full, shared by two runs
//! at once or left half-written by Ctrl-C gives a clear message or simply works.

mod common;

use common::tempdir;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// This test run's target folder: the runner cache of these tests (CARGO_TARGET_DIR),
/// where the checkout's crates are compiled already.
fn target() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    exe.ancestors().nth(3).unwrap().to_path_buf()
}

fn ferroc(dir: &Path, args: &[&str], env: &[(&str, &Path)]) -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_ferroc"));
    command
        .args(args)
        .current_dir(dir)
        .env("CARGO_TARGET_DIR", target())
        .env_remove("FERROC_CACHE");
    for (k, v) in env {
        command.env(k, v);
    }
    command
}

fn output(mut command: Command) -> (i32, String, String) {
    let out = command.output().expect("ferroc runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A library `lib` (crate `package`) in `dir` whose one module prints `word N`.
fn write_library(dir: &Path, lib: &str, package: &str, word: &str) {
    common::write_library_toml(dir, package, lib);
    std::fs::write(
        dir.join(format!("{lib}.lib.xml")),
        format!(
            r#"<library name="{lib}" version="0.1.0" rust-crate="{package}">
  <module-type name="Counter" rust="{lib}::Counter" doc="counts">
    <out name="count" type="f64"/>
  </module-type>
</library>
"#
        ),
    )
    .unwrap();
    std::fs::write(
        dir.join("src/lib.rs"),
        format!(
            r#"use ferroc_runtime::builder::Registry;
use ferroc_runtime::module::{{Module, ModuleType, Out, Setup}};

pub struct Counter {{ out: Out<f64>, n: f64 }}

impl ModuleType for Counter {{
    const NAME: &'static str = "{lib}.Counter";
    const DOC: &'static str = "counts";
    fn create(m: &mut Setup<'_>) -> Self {{
        Counter {{ out: m.output("count").build(), n: 0.0 }}
    }}
}}

impl Module for Counter {{
    fn update(&mut self) {{
        self.n += 1.0;
        self.out.publish(self.n);
        println!("{word} {{}}", self.n);
    }}
}}

pub fn register(registry: &mut Registry) {{
    registry.register::<Counter>();
}}
"#
        ),
    )
    .unwrap();
    std::fs::write(
        dir.join("app.xml"),
        format!(
            r#"<application name="app" version="1">
  <use library="{lib}" manifest="{lib}.lib.xml"/>
  <part name="p"><thread name="t" period="10ms">
    <module name="c" type="{lib}.Counter"/>
  </thread></part>
</application>
"#
        ),
    )
    .unwrap();
}

const RUN: [&str; 6] = ["run", "app.xml", "--lockstep", "--cycles", "2", "-q"];

/// The package folder of the runner linking the crate in `dir` (its libraries.txt).
fn package_of(cache: &Path, dir: &Path) -> PathBuf {
    let dir = dir.canonicalize().unwrap();
    for entry in std::fs::read_dir(cache.join("ferroc-runner"))
        .unwrap()
        .flatten()
    {
        let libraries =
            std::fs::read_to_string(entry.path().join("libraries.txt")).unwrap_or_default();
        if libraries.contains(&format!("({})", dir.display())) {
            return entry.path();
        }
    }
    panic!("no runner links {}", dir.display());
}

/// The one progress line before a build, checked: what, why, and an estimate only as
/// `about N s (the last … here)`.
fn progress_line<'a>(err: &'a str, library: &str, why: &str) -> &'a str {
    let line = err
        .lines()
        .find(|l| l.starts_with("building the runner of "))
        .unwrap_or_else(|| panic!("no progress line: {err}"));
    // "first use" in a fresh cache; where the test ran before, the cache has the runner
    // of the library's folder, whose crate the test has just written again, or which an
    // older checkout built.
    let rebuilt = format!("the crate of `{library}` changed");
    let again = [rebuilt.as_str(), "ferroc's sources changed"];
    let why = match again.iter().find(|r| line.contains(&format!(": {r}"))) {
        Some(reason) if why == "first use" => reason,
        _ => why,
    };
    let head = format!(
        "building the runner of `{library}` (debug) in {}: {why}",
        target().display()
    );
    assert!(line.starts_with(&head), "{line}\nexpected {head}");
    let rest = &line[head.len()..];
    assert!(
        rest.is_empty() || (rest.starts_with("; about ") && rest.ends_with(" here)")),
        "{line}"
    );
    line
}

#[test]
fn a_second_library_compiles_only_its_own_crate_and_a_small_main() {
    let first = tempdir("cache_first");
    write_library(&first, "tick", "tick-lib", "tick");
    let (code, out, err) = output(ferroc(&first, &RUN, &[]));
    assert_eq!(code, 0, "{err}");
    assert_eq!(out, "tick 1\ntick 2\n");
    progress_line(&err, "tick", "first use");
    assert!(err.contains("built the runner of `tick` in "), "{err}");
    assert!(
        !err.contains("Compiling"),
        "cargo's lines only with -v: {err}"
    );
    assert!(
        !first.join("target").exists(),
        "no target folder of its own"
    );

    // Another library: with -v, cargo's lines show what is compiled, and it is only
    // the library's crate and the runner's main.
    let second = tempdir("cache_second");
    write_library(&second, "tock", "tock-lib", "tock");
    let mut run = RUN.to_vec();
    run.push("-v");
    let started = std::time::SystemTime::now();
    let (code, out, err) = output(ferroc(&second, &run, &[]));
    assert_eq!(code, 0, "{err}");
    assert_eq!(out, "tock 1\ntock 2\n");
    progress_line(&err, "tock", "first use");
    let compiled: Vec<&str> = err
        .lines()
        .filter_map(|l| l.trim_start().strip_prefix("Compiling "))
        .collect();
    assert!(
        compiled.iter().any(|c| c.starts_with("tock-lib ")),
        "{compiled:?}"
    );
    for c in &compiled {
        assert!(
            c.starts_with("tock-lib ") || c.starts_with("ferroc-runner-"),
            "a second library compiled `{c}` again: {compiled:?}"
        );
    }
    assert!(
        err.contains("built the runner of `tock` in ") && err.contains(" compiled)"),
        "{err}"
    );
    // The record is written only by a build that did not wait for another's lock (its
    // time is its own); one left by an earlier run of these tests in this cache is not
    // this build's.
    let record = package_of(&target(), &second).join("last-build.txt");
    let written_now = std::fs::metadata(&record)
        .and_then(|m| m.modified())
        // (a second's margin: file times come from a coarser clock than SystemTime)
        .is_ok_and(|t| t + std::time::Duration::from_secs(1) >= started);
    if written_now {
        let record = std::fs::read_to_string(&record).unwrap();
        // (a rebuild where this test ran before in the same cache)
        let first = err.contains(": first use");
        let kind = if first { "new" } else { "rebuild" };
        assert!(
            record.contains(&format!("kind = {kind}\nprofile = debug\n")),
            "{record}"
        );
    }

    // A changed crate: rebuilt, and the line says why.
    let lib = std::fs::read_to_string(second.join("src/lib.rs")).unwrap();
    std::fs::write(second.join("src/lib.rs"), lib.replace("tock {}", "tack {}")).unwrap();
    let (code, out, err) = output(ferroc(&second, &RUN, &[]));
    assert_eq!(code, 0, "{err}");
    assert_eq!(out, "tack 1\ntack 2\n");
    progress_line(&err, "tock", "the crate of `tock` changed");
    // Nothing changed: no line at all.
    let (code, _, err) = output(ferroc(&second, &RUN, &[]));
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("building"), "{err}");

    // `ferroc cache` shows where, why there, and both runners.
    let (code, out, err) = output(ferroc(&first, &["cache"], &[]));
    assert_eq!(code, 0, "{err}");
    assert!(
        out.starts_with(&format!("cache: {}\n", target().display())),
        "{out}"
    );
    assert!(out.contains("CARGO_TARGET_DIR"), "{out}");
    assert!(out.contains("shared with the other builds there"), "{out}");
    for dir in [&first, &second] {
        let key = package_of(&target(), dir);
        let key = key.file_name().unwrap().to_str().unwrap();
        let line = out
            .lines()
            .find(|l| l.contains(key))
            .unwrap_or_else(|| panic!("{key} not listed: {out}"));
        assert!(
            line.contains(&dir.canonicalize().unwrap().display().to_string()),
            "{line}"
        );
        assert!(line.contains("built (debug)"), "{line}");
    }
}

#[test]
fn a_new_library_makes_no_target_and_starts_from_the_checkout_s_lock() {
    let dir = tempdir("cache_new_library");
    let (code, _, err) = output(ferroc(&dir, &["new", "library", "my_bot"], &[]));
    assert_eq!(code, 0, "{err}");
    let lib = dir.join("my_bot");
    let checkout_lock =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("Cargo.lock")).unwrap();
    assert_eq!(
        std::fs::read_to_string(lib.join("Cargo.lock")).unwrap(),
        checkout_lock
    );
    let config = std::fs::read_to_string(lib.join(".cargo/config.toml")).unwrap();
    assert!(
        config.contains(&format!("target-dir = {:?}", target().to_str().unwrap())),
        "{config}"
    );
    let (code, out, err) = output(ferroc(
        &dir,
        &[
            "run",
            "my_bot/demo.xml",
            "--lockstep",
            "--cycles",
            "1",
            "-q",
        ],
        &[],
    ));
    assert_eq!(code, 0, "{err}");
    assert_eq!(out, "[my_bot] total = 1.00\n");
    // The run wrote nothing into the library: no target folder, the lock as written.
    assert!(!lib.join("target").exists(), "a target folder of its own");
    assert_eq!(
        std::fs::read_to_string(lib.join("Cargo.lock")).unwrap(),
        checkout_lock
    );
    // `ferroc cache` without CARGO_TARGET_DIR names the checkout's target folder.
    let mut cache = ferroc(&dir, &["cache"], &[]);
    cache.env_remove("CARGO_TARGET_DIR");
    let (code, out, _) = output(cache);
    assert_eq!(code, 0);
    let checkout = Path::new(env!("CARGO_MANIFEST_DIR")).join("target");
    assert!(
        out.starts_with(&format!("cache: {}\n", checkout.display())),
        "{out}"
    );
    assert!(
        out.contains("the target folder of ferroc's checkout"),
        "{out}"
    );
}

/// A cache folder with a runner's files and a developer's own among them.
fn fill_cache(dir: &Path) {
    let key = "0123456789abcdef";
    for (path, text) in [
        (format!("ferroc-runner/{key}/Cargo.toml"), "x"),
        (format!("ferroc-runner/{key}/libraries.txt"), "tick (/x)"),
        (format!("debug/ferroc-runner-{key}"), "exe"),
        (format!("debug/ferroc-runner-{key}.d"), "dep"),
        (format!("debug/deps/ferroc_runner_{key}-1a2b3c"), "exe"),
        (
            format!("debug/.fingerprint/ferroc-runner-{key}-1a2b3c/bin"),
            "f",
        ),
        ("debug/deps/libmine-1a2b3c.rlib".to_string(), "mine"),
        ("debug/mine".to_string(), "mine"),
        ("release/.fingerprint/serde-1a2b3c/lib".to_string(), "f"),
    ] {
        let file = dir.join(path);
        std::fs::create_dir_all(file.parent().unwrap()).unwrap();
        std::fs::write(file, text).unwrap();
    }
}

#[test]
fn clean_removes_only_the_runners_in_a_shared_folder_and_everything_in_ferroc_s_own() {
    let base = tempdir("cache_clean");
    // A folder ferroc did not make (no marker): its other builds stay.
    let shared = base.join("shared");
    fill_cache(&shared);
    let env = [("FERROC_CACHE", shared.as_path())];
    let (code, out, err) = output(ferroc(&base, &["cache", "--clean", "--dry-run"], &env));
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("would remove"), "{out}");
    assert!(out.contains("only the runners' own files"), "{out}");
    assert!(
        out.contains("debug/ferroc-runner-0123456789abcdef\n"),
        "{out}"
    );
    assert!(!out.contains("mine"), "{out}");
    assert!(
        shared.join("debug/ferroc-runner-0123456789abcdef").exists(),
        "dry run"
    );
    let (code, out, err) = output(ferroc(&base, &["cache", "--clean"], &env));
    assert_eq!(code, 0, "{err}");
    assert!(out.ends_with("removed\n"), "{out}");
    let mut left = Vec::new();
    walk(&shared, &shared, &mut left);
    left.sort();
    assert_eq!(
        left,
        [
            "debug/deps/libmine-1a2b3c.rlib",
            "debug/mine",
            "release/.fingerprint/serde-1a2b3c/lib"
        ]
    );

    // A folder ferroc made for itself (marked): emptied but for the marker.
    let own = base.join("own");
    fill_cache(&own);
    std::fs::write(own.join("ferroc-cache.txt"), "ferroc's").unwrap();
    let env = [("FERROC_CACHE", own.as_path())];
    let (code, out, err) = output(ferroc(&base, &["cache"], &env));
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("all of it ferroc's"), "{out}");
    assert!(
        out.contains("0123456789abcdef  tick (/x)  built (debug)"),
        "{out}"
    );
    let (code, _, err) = output(ferroc(&base, &["cache", "--clean"], &env));
    assert_eq!(code, 0, "{err}");
    let mut left = Vec::new();
    walk(&own, &own, &mut left);
    assert_eq!(left, ["ferroc-cache.txt"]);

    // A folder not made yet: said so, nothing to clean.
    let env = [("FERROC_CACHE", base.join("none"))];
    let env: Vec<(&str, &Path)> = env.iter().map(|(k, v)| (*k, v.as_path())).collect();
    let (code, out, _) = output(ferroc(&base, &["cache"], &env));
    assert_eq!(code, 0);
    assert!(out.contains("nothing built yet"), "{out}");
    let (code, out, _) = output(ferroc(&base, &["cache", "--clean"], &env));
    assert_eq!(code, 0, "{out}");
}

fn walk(root: &Path, dir: &Path, out: &mut Vec<String>) {
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        if e.path().is_dir() {
            walk(root, &e.path(), out);
        } else {
            let rel = e.path().strip_prefix(root).unwrap().to_path_buf();
            out.push(rel.to_string_lossy().into_owned());
        }
    }
}

#[test]
fn a_read_only_or_full_cache_is_named_with_what_to_do() {
    let base = tempdir("cache_unusable");
    write_library(&base, "tick", "tick-ro", "tick");
    let ro = base.join("ro");
    std::fs::create_dir_all(&ro).unwrap();
    // root writes through permissions: a read-only tmpfs instead.
    let _disk;
    if is_root() {
        _disk = common::SmallDisk::mount_with(&ro, "ro,size=64k");
        if _disk.is_none() {
            return;
        }
    } else {
        set_mode(&ro, 0o555);
    }
    let (code, out, err) = output(ferroc(&base, &RUN, &[("FERROC_CACHE", &ro)]));
    assert_eq!(code, 2, "{out}{err}");
    assert!(
        err.contains(&format!(
            "error: the runner cache {} is not writable",
            ro.display()
        )),
        "{err}"
    );
    assert!(
        err.contains("help: make it writable, or name another folder for them: FERROC_CACHE=DIR"),
        "{err}"
    );
    assert!(!err.contains("building"), "{err}");
    if !is_root() {
        set_mode(&ro, 0o755);
    }

    // Full: too small for the runner's package, or for what cargo compiles.
    for size in ["64k", "2m"] {
        let full = base.join(format!("full-{size}"));
        let Some(_disk) = common::SmallDisk::mount(&full, size) else {
            return;
        };
        let (code, out, err) = output(ferroc(&base, &RUN, &[("FERROC_CACHE", &full)]));
        assert_eq!(code, 2, "{size}: {out}{err}");
        assert!(
            err.contains(&format!(
                "error: the runner cache {} is full",
                full.display()
            )),
            "{size}: {err}"
        );
        assert!(
            err.contains("free space there (`ferroc cache --clean`"),
            "{err}"
        );
        assert!(!err.contains("panicked"), "{err}");
    }
}

fn is_root() -> bool {
    Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0")
}

fn set_mode(dir: &Path, mode: u32) {
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(dir, std::fs::Permissions::from_mode(mode)).unwrap();
}

#[test]
fn two_runs_of_different_libraries_at_once_both_build_and_leave_the_cache_usable() {
    let base = tempdir("cache_concurrent");
    let dirs = [base.join("one"), base.join("two")];
    write_library(&dirs[0], "uno", "uno-lib", "uno");
    write_library(&dirs[1], "dos", "dos-lib", "dos");
    let children: Vec<_> = dirs
        .iter()
        .map(|d| {
            ferroc(d, &RUN, &[])
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn()
                .unwrap()
        })
        .collect();
    for (child, word) in children.into_iter().zip(["uno", "dos"]) {
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{word}: {err}");
        assert_eq!(
            String::from_utf8_lossy(&out.stdout),
            format!("{word} 1\n{word} 2\n")
        );
    }
    // Both runners are whole: they start without a build.
    for (d, word) in dirs.iter().zip(["uno", "dos"]) {
        let (code, out, err) = output(ferroc(d, &RUN, &[]));
        assert_eq!(code, 0, "{err}");
        assert_eq!(out, format!("{word} 1\n{word} 2\n"));
        assert!(!err.contains("building"), "{err}");
    }
}

#[test]
fn a_build_stopped_by_ctrl_c_leaves_nothing_that_breaks_the_next_run() {
    use std::os::unix::process::CommandExt;
    let dir = tempdir("cache_interrupted");
    write_library(&dir, "stop", "stop-lib", "stop");
    let mut child = ferroc(&dir, &RUN, &[])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .process_group(0)
        .spawn()
        .unwrap();
    // Ctrl-C as a terminal sends it: to the whole group (ferroc, cargo, rustc), once
    // the build has started.
    let mut stderr = child.stderr.take().unwrap();
    let mut seen = String::new();
    let mut buffer = [0u8; 256];
    while !seen.contains("building the runner") {
        match stderr.read(&mut buffer) {
            Ok(0) | Err(_) => break,
            Ok(n) => seen.push_str(&String::from_utf8_lossy(&buffer[..n])),
        }
    }
    assert!(seen.contains("building the runner"), "{seen}");
    // The shell's own `kill`: procps-ng 4.0.2's /usr/bin/kill turns `-INT -12345` into
    // kill(-1, SIGINT) (strace shows only the first digit kept), which signals every
    // process the user may signal; it stopped whole sessions here. The builtin with `--`
    // signals the group meant.
    let sent = Command::new("sh")
        .args(["-c", "kill -s INT -- \"-$1\"", "sh"])
        .arg(child.id().to_string())
        .status()
        .unwrap();
    assert!(sent.success(), "no process group {}", child.id());
    let _ = child.wait();
    // What a crash mid-write would leave besides: a temporary file, a cut main.rs.
    let package = package_of(&target(), &dir);
    std::fs::write(package.join("Cargo.toml.tmp999999"), "[package").unwrap();
    let main = std::fs::read_to_string(package.join("src/main.rs")).unwrap();
    std::fs::write(package.join("src/main.rs"), &main[..main.len() / 2]).unwrap();
    let (code, out, err) = output(ferroc(&dir, &RUN, &[]));
    assert_eq!(code, 0, "{err}");
    assert_eq!(out, "stop 1\nstop 2\n");
    assert_eq!(
        std::fs::read_to_string(package.join("src/main.rs")).unwrap(),
        main
    );
}
