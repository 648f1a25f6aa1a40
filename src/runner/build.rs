//! Building a runner with cargo, telling the truth about it: one line saying what is
//! built and why, with the time the last build of the same kind took in this cache
//! (recorded next to each runner; no number when there is none), cargo's own output
//! only with `-v`, a library's compile errors always in full, and the time it took.

use super::crates::LibraryCrate;
use super::failure::{failed_package, strip_ansi, unfetched};
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

/// The file next to a runner's package recording its last successful build.
pub const RECORD: &str = "last-build.txt";

/// What a build has to do, as far as ferroc can tell before cargo runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kind {
    /// Nothing of ferroc compiled in this cache for this profile yet.
    Cold,
    /// A runner not built before; ferroc's crates were compiled here already.
    New,
    /// A runner built before, one of its inputs changed.
    Rebuild,
}

impl Kind {
    fn name(self) -> &'static str {
        match self {
            Kind::Cold => "cold",
            Kind::New => "new",
            Kind::Rebuild => "rebuild",
        }
    }

    fn what(self) -> &'static str {
        match self {
            Kind::Cold => "first build of a runner here",
            Kind::New => "first use",
            Kind::Rebuild => "rebuild",
        }
    }
}

/// One runner build: the crates it links, its package folder, the cache, the profile.
pub struct Build<'a> {
    pub crates: &'a [LibraryCrate],
    pub package: &'a Path,
    pub target: &'a Path,
    pub profile: &'a str,
    pub kind: Kind,
    /// Why it is built, in words ("first use", "`beep`'s crate changed").
    pub why: String,
    pub verbose: bool,
}

/// What cargo's output said.
#[derive(Default)]
pub struct Outcome {
    pub success: bool,
    /// Packages that failed to compile.
    pub failed: Vec<String>,
    /// Registry crates of the libraries that could not be fetched.
    pub unavailable: Vec<String>,
    /// A line saying the disk is full (cargo's or rustc's words).
    pub full: Option<String>,
    /// Units compiled (cargo's `Compiling` lines).
    pub compiled: usize,
    /// cargo waited for another build's lock (the time is not this build's alone).
    pub waited: bool,
}

/// The kind of build `exe` needs in `target` when it is not fresh.
pub fn kind(exe: &Path, target: &Path, profile: &str) -> Kind {
    if exe.is_file() {
        return Kind::Rebuild;
    }
    let fingerprints = target.join(profile).join(".fingerprint");
    let host_built = std::fs::read_dir(fingerprints).is_ok_and(|entries| {
        entries.flatten().any(|e| {
            e.file_name()
                .to_string_lossy()
                .starts_with("ferroc-runtime-")
        })
    });
    if host_built {
        Kind::New
    } else {
        Kind::Cold
    }
}

/// Runs cargo for `b`: the line before, the line after, the record on success.
pub fn build(b: &Build) -> std::io::Result<Outcome> {
    let libraries = names(b.crates);
    let estimate = match estimate(b.target, b.profile, b.kind) {
        Some(seconds) => format!(
            "; about {} (the last {} here)",
            duration(seconds),
            b.kind.what()
        ),
        None => String::new(),
    };
    eprintln!(
        "building the runner of {libraries} ({}) in {}: {}{estimate}",
        b.profile,
        b.target.display(),
        b.why
    );
    let start = Instant::now();
    let mut child = cargo(b).spawn()?;
    let mut outcome = match child.stderr.take() {
        Some(err) => follow(err, b),
        None => Outcome::default(),
    };
    outcome.success = child.wait().is_ok_and(|s| s.success());
    let seconds = start.elapsed().as_secs_f64();
    if outcome.success {
        eprintln!(
            "built the runner of {libraries} in {} ({} compiled)",
            duration(seconds),
            plural(outcome.compiled, "crate")
        );
        if !outcome.waited {
            record(b, seconds, outcome.compiled);
        }
    }
    Ok(outcome)
}

fn names(crates: &[LibraryCrate]) -> String {
    crates
        .iter()
        .map(|c| format!("`{}`", c.library))
        .collect::<Vec<_>>()
        .join(", ")
}

fn plural(n: usize, what: &str) -> String {
    if n == 1 {
        format!("1 {what}")
    } else {
        format!("{n} {what}s")
    }
}

/// `41 s`, `2 min 5 s`.
pub fn duration(seconds: f64) -> String {
    let s = seconds.round() as u64;
    if s < 60 {
        format!("{s} s")
    } else {
        format!("{} min {} s", s / 60, s % 60)
    }
}

/// `cargo build` of the runner package into the cache, its errors piped.
fn cargo(b: &Build) -> Command {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut command = Command::new(cargo);
    command
        .arg("build")
        .arg("--manifest-path")
        .arg(b.package.join("Cargo.toml"))
        .arg("--target-dir")
        .arg(b.target)
        .args((b.profile == "release").then_some("--release"))
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    // cargo sees a pipe: say whether to colour (ferroc's --color, for its stderr).
    let colours = crate::color::enabled(crate::color::Stream::Stderr);
    command.arg(if colours {
        "--color=always"
    } else {
        "--color=never"
    });
    if std::io::stderr().is_terminal() {
        // With -v, cargo's progress bar all the same.
        if b.verbose {
            let width = std::env::var("COLUMNS")
                .ok()
                .and_then(|c| c.parse::<u16>().ok())
                .unwrap_or(80);
            command.args(["--config", "term.progress.when=\"always\"", "--config"]);
            command.arg(format!("term.progress.width={width}"));
        }
    }
    command
}

/// cargo's output: all of it passed on with `-v`, else all but its status lines
/// (`Compiling …`), so warnings and errors are shown in full as they come.
fn follow(mut err: impl std::io::Read, b: &Build) -> Outcome {
    let mut outcome = Outcome::default();
    let mut stderr = std::io::stderr();
    let mut line = Vec::new();
    let mut buffer = [0u8; 4096];
    loop {
        let n = match err.read(&mut buffer) {
            Ok(0) | Err(_) => break,
            Ok(n) => n,
        };
        if b.verbose {
            let _ = stderr.write_all(&buffer[..n]);
        }
        for &byte in &buffer[..n] {
            if byte == b'\n' || byte == b'\r' {
                let text = String::from_utf8_lossy(&line).into_owned();
                read_line(&text, b, &mut outcome);
                if !b.verbose && byte == b'\n' && !is_status(&text) {
                    let _ = writeln!(stderr, "{text}");
                }
                line.clear();
            } else if line.len() < 64 * 1024 {
                line.push(byte);
            }
        }
    }
    outcome
}

/// What one of cargo's lines tells about the build.
fn read_line(text: &str, b: &Build, outcome: &mut Outcome) {
    let plain = strip_ansi(text);
    if let Some(package) = failed_package(&plain) {
        outcome.failed.push(package);
    }
    for c in b.crates.iter().filter(|c| c.version.is_some()) {
        if unfetched(&plain, &c.package) && !outcome.unavailable.contains(&c.package) {
            outcome.unavailable.push(c.package.clone());
        }
    }
    if outcome.full.is_none() && super::cache::says_full(&plain) {
        outcome.full = Some(plain.trim().to_string());
    }
    match status_word(&plain) {
        Some("Compiling") => outcome.compiled += 1,
        Some("Blocking") if !outcome.waited => {
            outcome.waited = true;
            eprintln!(
                "waiting for another build in {} to finish (cargo's lock keeps the cache whole)",
                b.target.display()
            );
        }
        _ => {}
    }
}

/// The verb of one of cargo's status lines (`   Compiling foo v1`: right-aligned in
/// twelve columns), or `None` for any other line (diagnostics, notes, code).
fn status_word(plain: &str) -> Option<&str> {
    let head = plain.get(..12)?;
    let word = head.trim_start();
    let rest = plain.get(12..)?;
    let is_word = !word.is_empty()
        && word.starts_with(|c: char| c.is_ascii_uppercase())
        && word.chars().all(|c| c.is_ascii_alphabetic());
    (is_word && (rest.starts_with(' ') || rest.is_empty())).then_some(word)
}

fn is_status(text: &str) -> bool {
    let plain = strip_ansi(text);
    status_word(&plain).is_some() || is_unmatched_profile(&plain)
}

/// cargo's warning about a `[profile.*.package.NAME]` table for a crate the runner does
/// not link: the runner copies ferroc's profile tables whole (`program::profiles`), and
/// those for crates only other runner kinds link (Zenoh's, for the plain runner) are
/// expected to match nothing; not the user's to act on (shown with `-v`).
fn is_unmatched_profile(plain: &str) -> bool {
    plain.starts_with("warning: profile package spec `")
        && plain.contains("did not match any packages")
}

/// Writes the record of a successful build next to the runner's package.
fn record(b: &Build, seconds: f64, compiled: usize) {
    let text = format!(
        "kind = {}\nprofile = {}\nseconds = {seconds:.1}\ncompiled = {compiled}\n",
        b.kind.name(),
        b.profile
    );
    let path = b.package.join(RECORD);
    let temporary = path.with_extension(format!("tmp{}", std::process::id()));
    if std::fs::write(&temporary, text).is_ok() && std::fs::rename(&temporary, &path).is_err() {
        let _ = std::fs::remove_file(&temporary);
    }
}

/// A runner's record: (kind, profile, seconds, crates compiled).
pub fn read_record(package: &Path) -> Option<(String, String, f64, usize)> {
    let text = std::fs::read_to_string(package.join(RECORD)).ok()?;
    let value = |key: &str| {
        text.lines()
            .find_map(|l| l.strip_prefix(key)?.trim_start().strip_prefix('='))
            .map(str::trim)
    };
    Some((
        value("kind")?.to_string(),
        value("profile")?.to_string(),
        value("seconds")?.parse().ok()?,
        value("compiled")?.parse().ok()?,
    ))
}

/// The seconds of the newest recorded build of `kind` and `profile` in this cache.
pub fn estimate(target: &Path, profile: &str, kind: Kind) -> Option<f64> {
    let packages = std::fs::read_dir(target.join(super::cache::PACKAGES)).ok()?;
    let mut newest: Option<(std::time::SystemTime, f64)> = None;
    for package in packages.flatten().map(|e| e.path()) {
        let Some((k, p, seconds, _)) = read_record(&package) else {
            continue;
        };
        let when = std::fs::metadata(package.join(RECORD)).and_then(|m| m.modified());
        if k == kind.name() && p == profile {
            if let Ok(when) = when {
                if newest.is_none_or(|(t, _)| when > t) {
                    newest = Some((when, seconds));
                }
            }
        }
    }
    newest.map(|(_, s)| s)
}

/// Why a runner that is not fresh is built: which input changed, in words.
pub fn why(
    kind: Kind,
    changed: Option<&Path>,
    crates: &[LibraryCrate],
    source: &Path,
    package: &Path,
) -> String {
    match (kind, changed) {
        (Kind::Cold, _) => "first use; nothing of ferroc is compiled in this cache yet".into(),
        (Kind::New, _) => "first use".into(),
        (Kind::Rebuild, Some(path)) => {
            if let Some(c) = crates.iter().find(|c| path.starts_with(&c.dir)) {
                format!("the crate of `{}` changed", c.library)
            } else if path.starts_with(source) {
                "ferroc's sources changed".into()
            } else if path.starts_with(package) {
                "its package changed (another ferroc, or the checkout's Cargo.lock)".into()
            } else {
                format!("{} changed", path.display())
            }
        }
        (Kind::Rebuild, None) => "its build record is missing".into(),
    }
}

/// The executable of runner `name` in `target` for `profile`.
pub fn executable(target: &Path, profile: &str, name: &str) -> PathBuf {
    target.join(profile).join(name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cargo_status_lines_are_told_from_diagnostics() {
        assert_eq!(status_word("   Compiling beep v0.1.0"), Some("Compiling"));
        assert_eq!(
            status_word("    Blocking waiting for file lock on build directory"),
            Some("Blocking")
        );
        assert_eq!(status_word("    Finished `dev` profile"), Some("Finished"));
        assert!(is_status("\x1b[1m\x1b[32m   Compiling\x1b[0m beep v0.1.0"));
        for other in [
            "error[E0308]: mismatched types",
            "  --> src/lib.rs:3:5",
            "   = note: expected `f64`",
            "3 |     self.n += true;",
            "warning: unused variable: `x`",
            "error: could not compile `beep` (lib) due to 1 previous error",
        ] {
            assert_eq!(status_word(other), None, "{other}");
            assert!(!is_status(other), "{other}");
        }
        // Profile tables of crates this runner does not link: hidden (shown with -v);
        // a warning about the user's code is not.
        assert!(is_status(
            "\x1b[1m\x1b[33mwarning\x1b[0m: profile package spec `zenoh-config` in profile `release` did not match any packages"
        ));
        assert!(!is_status(
            "warning: profile package spec is what `beep` calls its spec"
        ));
    }

    #[test]
    fn durations_read_as_a_person_says_them() {
        assert_eq!(duration(0.4), "0 s");
        assert_eq!(duration(41.4), "41 s");
        assert_eq!(duration(125.0), "2 min 5 s");
    }

    #[test]
    fn the_estimate_is_the_newest_build_of_the_same_kind_or_none() {
        let target = std::env::temp_dir().join(format!("ferroc-estimate-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&target);
        let package = |key: &str, text: &str| {
            let dir = target.join(super::super::cache::PACKAGES).join(key);
            std::fs::create_dir_all(&dir).unwrap();
            std::fs::write(dir.join(RECORD), text).unwrap();
        };
        assert_eq!(estimate(&target, "release", Kind::New), None, "no cache");
        package(
            "a",
            "kind = new\nprofile = release\nseconds = 41.0\ncompiled = 3\n",
        );
        package(
            "b",
            "kind = rebuild\nprofile = release\nseconds = 4.0\ncompiled = 1\n",
        );
        package(
            "c",
            "kind = new\nprofile = debug\nseconds = 9.0\ncompiled = 3\n",
        );
        package("d", "half a rec");
        assert_eq!(estimate(&target, "release", Kind::New), Some(41.0));
        assert_eq!(estimate(&target, "release", Kind::Rebuild), Some(4.0));
        assert_eq!(estimate(&target, "debug", Kind::New), Some(9.0));
        assert_eq!(
            estimate(&target, "release", Kind::Cold),
            None,
            "never invented"
        );
        std::fs::remove_dir_all(&target).unwrap();
    }
}
