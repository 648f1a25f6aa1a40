//! The runner program of a set of libraries: generated once, built by cargo in the
//! libraries' target folder, rebuilt only when one of its sources changed.
//!
//! The package lives in `TARGET/ferroc-runner/KEY/` (KEY: a hash of the libraries'
//! crates, ferroc's sources and the profile), its binary in `TARGET/PROFILE/`. Sharing
//! the target folder with the libraries' own workspace means their dependencies are
//! compiled once for both. A model is not part of the runner: the runner checks and
//! is handed the plan of the model (or, the inspecting kind, checks it), so editing a
//! model never rebuilds anything.
//!
//! Two kinds of runner per set of libraries ([`Kind`]), each its own package with one
//! feature set, sharing the target folder: the plain runner links `ferroc-runner`
//! (the runtime, the standard library, no compiler, no Zenoh); the inspecting runner
//! (`ferroc run --inspect`) links `ferroc-host` with the compiler and the inspection
//! server.

use super::crates::LibraryCrate;
use super::failure::{failed_package, report_failure, unfetched};
use super::source_dir;
use crate::bundle::text::{comment, toml_str};
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};

/// The cargo profile runners are built with: ferroc's own (a release ferroc runs
/// release runners).
fn profile() -> (&'static str, Option<&'static str>) {
    if cfg!(debug_assertions) {
        ("debug", None)
    } else {
        ("release", Some("--release"))
    }
}

/// What a runner links, by what the run asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// `ferroc run` and `ferroc types`: `ferroc-runner` (no compiler, no Zenoh).
    Plain,
    /// `ferroc run --inspect`: `ferroc-host`, with the inspection server on Zenoh and
    /// the compiler that checks structural edits.
    Inspect,
}

impl Kind {
    /// The workspace crate the runner depends on: its folder and package name.
    fn host_crate(self) -> (&'static str, &'static str) {
        match self {
            Kind::Plain => ("runner", "ferroc-runner"),
            Kind::Inspect => ("host", "ferroc-host"),
        }
    }

    /// Its name in the runner's key and messages.
    fn name(self) -> &'static str {
        match self {
            Kind::Plain => "plain",
            Kind::Inspect => "inspect",
        }
    }
}

/// A built runner of this kind for `crates`: its executable, built now if needed
/// (cargo's progress on stderr). On failure the cause is reported, pointing at the
/// manifests.
pub fn ensure(crates: &[LibraryCrate], kind: Kind) -> Result<PathBuf, ExitCode> {
    let source = source_dir();
    let host = source.join(kind.host_crate().0);
    if !host.join("Cargo.toml").is_file() {
        eprintln!(
            "error: ferroc's sources are not at {} (a runner for your libraries is built from them)\n  \
             help: set FERROC_SOURCE to a ferroc checkout of version {}",
            source.display(),
            env!("CARGO_PKG_VERSION")
        );
        return Err(ExitCode::from(2));
    }
    let (profile, flag) = profile();
    let key = key(&source, crates, &format!("{profile} {}", kind.name()));
    let target = target_dir(crates);
    let name = format!("ferroc-runner-{key}");
    let dir = target.join("ferroc-runner").join(&key);
    let exe = target.join(profile).join(&name);
    if let Err(e) = write_package(&dir, &name, kind, &host, crates, &source) {
        eprintln!(
            "error: cannot write the runner package in {}: {e}",
            dir.display()
        );
        return Err(ExitCode::from(2));
    }
    if is_fresh(&exe, &dir, crates) {
        return Ok(exe);
    }
    // Before cargo: a crate linking another ferroc-runtime would fail with cargo's
    // lockfile collision, which does not say what to do.
    let runtime = source.join("runtime");
    let conflicts = super::checkout::conflicts(crates, &runtime.canonicalize().unwrap_or(runtime));
    if !conflicts.is_empty() {
        for c in &conflicts {
            eprintln!("{c}");
        }
        return Err(ExitCode::from(1));
    }
    eprintln!(
        "building the runner of {} in {} (first use, or a crate changed)",
        crates
            .iter()
            .map(|c| format!("`{}`", c.library))
            .collect::<Vec<_>>()
            .join(", "),
        target.display()
    );
    let mut child = match cargo_build(&dir, &target, flag).spawn() {
        Ok(c) => c,
        Err(e) => {
            eprintln!("error: cannot start cargo to build the runner: {e}\n  help: install Rust (rustup.rs) or set CARGO to cargo's path");
            return Err(ExitCode::from(2));
        }
    };
    let (failed, unavailable) = match child.stderr.take() {
        Some(err) => follow_cargo(err, crates),
        None => (Vec::new(), Vec::new()),
    };
    let status = child.wait();
    if status.as_ref().is_ok_and(|s| s.success()) && exe.is_file() {
        return Ok(exe);
    }
    report_failure(crates, &failed, &unavailable, &name, &dir);
    Err(ExitCode::from(1))
}

/// `cargo build` of the runner package in `dir` into `target`, its errors piped.
fn cargo_build(dir: &Path, target: &Path, flag: Option<&str>) -> Command {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut command = Command::new(cargo);
    command
        .arg("build")
        .arg("--manifest-path")
        .arg(dir.join("Cargo.toml"))
        .arg("--target-dir")
        .arg(target)
        .args(flag)
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
        // Ask for cargo's progress bar all the same.
        let width = std::env::var("COLUMNS")
            .ok()
            .and_then(|c| c.parse::<u16>().ok())
            .unwrap_or(80);
        command.args(["--config", "term.progress.when=\"always\"", "--config"]);
        command.arg(format!("term.progress.width={width}"));
    }
    command
}

/// cargo's output passed on as it comes (progress bar included); the packages that
/// failed to compile, and the registry crates of `crates` that could not be fetched.
fn follow_cargo(
    mut err: impl std::io::Read,
    crates: &[LibraryCrate],
) -> (Vec<String>, Vec<String>) {
    let mut failed = Vec::new();
    let mut unavailable: Vec<String> = Vec::new();
    let mut stderr = std::io::stderr();
    let mut line = Vec::new();
    let mut buffer = [0u8; 4096];
    loop {
        let n = match err.read(&mut buffer) {
            Ok(0) | Err(_) => break,
            Ok(n) => n,
        };
        let _ = stderr.write_all(&buffer[..n]);
        for &b in &buffer[..n] {
            if b == b'\n' || b == b'\r' {
                let text = String::from_utf8_lossy(&line);
                if let Some(package) = failed_package(&text) {
                    failed.push(package);
                }
                for c in crates.iter().filter(|c| c.version.is_some()) {
                    if unfetched(&text, &c.package) && !unavailable.contains(&c.package) {
                        unavailable.push(c.package.clone());
                    }
                }
                line.clear();
            } else if line.len() < 4096 {
                line.push(b);
            }
        }
    }
    (failed, unavailable)
}

/// A short stable name for this set of crates with these sources and profile.
fn key(source: &Path, crates: &[LibraryCrate], profile: &str) -> String {
    let mut text = format!(
        "ferroc {}\n{}\n{profile}\n",
        env!("CARGO_PKG_VERSION"),
        source.display()
    );
    for c in crates {
        text.push_str(&format!(
            "{}\n{}\n{}\n",
            c.package,
            c.dir.display(),
            c.version.as_deref().unwrap_or("")
        ));
    }
    crate::bundle::sha256::hex(text.as_bytes())[..16].to_string()
}

/// `CARGO_TARGET_DIR` if set; else the `target/` of the first library's workspace (the
/// nearest folder above its crate whose Cargo.toml declares `[workspace]`), or of the
/// crate itself.
fn target_dir(crates: &[LibraryCrate]) -> PathBuf {
    target_dir_from(std::env::var_os("CARGO_TARGET_DIR"), &crates[0].dir)
}

fn target_dir_from(env: Option<std::ffi::OsString>, first: &Path) -> PathBuf {
    if let Some(dir) = env.filter(|d| !d.is_empty()) {
        let dir = PathBuf::from(dir);
        return std::path::absolute(&dir).unwrap_or(dir);
    }
    let root = first
        .ancestors()
        .find(|d| {
            std::fs::read_to_string(d.join("Cargo.toml"))
                .is_ok_and(|t| t.lines().any(|l| l.trim() == "[workspace]"))
        })
        .unwrap_or(first);
    root.join("target")
}

/// Writes the runner's Cargo.toml, main.rs and (first time) Cargo.lock, each only when
/// its text changes, through a rename (runs started together write the same files).
fn write_package(
    dir: &Path,
    name: &str,
    kind: Kind,
    host: &Path,
    crates: &[LibraryCrate],
    source: &Path,
) -> std::io::Result<()> {
    std::fs::create_dir_all(dir.join("src"))?;
    let toml = cargo_toml(name, kind, host, crates);
    let main = main_rs(kind, crates);
    replace_if_changed(&dir.join("Cargo.toml"), toml.as_bytes())?;
    replace_if_changed(&dir.join("src/main.rs"), main.as_bytes())?;
    let lock = dir.join("Cargo.lock");
    if !lock.exists() {
        // The versions ferroc is built and tested with (cargo adds the libraries' own).
        if let Ok(text) = std::fs::read(source.join("Cargo.lock")) {
            replace_if_changed(&lock, &text)?;
        }
    }
    Ok(())
}

/// The runner's main.rs: the registry of the standard library's types and the
/// libraries', handed to the kind's `main`.
fn main_rs(kind: Kind, crates: &[LibraryCrate]) -> String {
    let version = env!("CARGO_PKG_VERSION");
    let (what, krate, registry) = match kind {
        Kind::Plain => (
            "runs the plans `ferroc run` hands it and describes its module types",
            "ferroc_runner",
            "ferroc_runner::registry()",
        ),
        Kind::Inspect => (
            "runs `ferroc run --inspect`",
            "ferroc_host",
            "ferroc_host::run::registry()",
        ),
    };
    let mut main = format!(
        "//! Generated by ferroc {version}: {what}, with the module\n\
         //! types of the standard library and of the libraries linked here.\n\n\
         /// The allocator ferroc itself uses (applications allocate as under ferroc).\n\
         #[global_allocator]\n\
         static GLOBAL: {krate}::mimalloc::MiMalloc = {krate}::mimalloc::MiMalloc;\n\n\
         fn main() -> std::process::ExitCode {{\n    let mut registry = {registry};\n"
    );
    for (i, c) in crates.iter().enumerate() {
        main.push_str(&format!(
            "    // The library `{}`.\n    library_{i}::register(&mut registry);\n",
            comment(&c.library)
        ));
    }
    main.push_str(&format!("    {krate}::main(registry)\n}}\n"));
    main
}

/// The runner's Cargo.toml: the kind's ferroc crate by path, each library's crate by
/// path or, for `rust-crate="PACKAGE@VERSION"`, by version from the registry.
fn cargo_toml(name: &str, kind: Kind, host: &Path, crates: &[LibraryCrate]) -> String {
    let libraries: Vec<String> = crates
        .iter()
        .map(|c| format!("{} ({})", comment(&c.library), comment(&c.package)))
        .collect();
    let mut toml = format!(
        "# Generated by ferroc {}: the runner of the libraries {}.\n\
         # ferroc rewrites this file; build output goes to the libraries' target folder.\n\
         [package]\nname = \"{name}\"\nversion = \"0.0.0\"\nedition = \"2021\"\npublish = false\n\n\
         [dependencies]\n{} = {{ path = {} }}\n",
        env!("CARGO_PKG_VERSION"),
        libraries.join(", "),
        kind.host_crate().1,
        toml_str(&host.to_string_lossy())
    );
    for (i, c) in crates.iter().enumerate() {
        let source = match &c.version {
            Some(version) => format!("version = {}", toml_str(version)),
            None => format!("path = {}", toml_str(&c.dir.to_string_lossy())),
        };
        toml.push_str(&format!(
            "library_{i} = {{ package = {}, {source} }}\n",
            toml_str(&c.package),
        ));
    }
    // The checkout's profile, so that its already compiled dependencies are reused.
    toml.push_str("\n[profile.release]\ndebug = 1\n\n# Not a member of any enclosing workspace.\n[workspace]\n");
    toml
}

fn replace_if_changed(path: &Path, text: &[u8]) -> std::io::Result<()> {
    if std::fs::read(path).is_ok_and(|old| old == text) {
        return Ok(());
    }
    let temporary = path.with_extension(format!("tmp{}", std::process::id()));
    std::fs::write(&temporary, text)?;
    std::fs::rename(&temporary, path).inspect_err(|_| {
        let _ = std::fs::remove_file(&temporary);
    })
}

/// Whether `exe` is newer than everything it was built from: the source files cargo
/// listed in its dep-info (`exe.d`: every local crate's sources), the Cargo.toml of
/// the runner, of ferroc's host crate and of every library crate, and the lock file.
/// Anything else (or no dep-info) leaves the decision to cargo.
fn is_fresh(exe: &Path, dir: &Path, crates: &[LibraryCrate]) -> bool {
    let Some(built) = modified(exe) else {
        return false;
    };
    let Ok(dep_info) = std::fs::read_to_string(exe.with_extension("d")) else {
        return false;
    };
    let Some((_, deps)) = dep_info.split_once(": ") else {
        return false;
    };
    let mut inputs: Vec<PathBuf> = split_dep_info(deps);
    if inputs.is_empty() {
        return false;
    }
    inputs.push(dir.join("Cargo.toml"));
    inputs.push(dir.join("Cargo.lock"));
    inputs.push(source_dir().join("host/Cargo.toml"));
    inputs.push(source_dir().join("runner/Cargo.toml"));
    // (A registry crate's sources are in cargo's cache, listed in the dep-info.)
    inputs
        .extend((crates.iter().filter(|c| c.version.is_none())).map(|c| c.dir.join("Cargo.toml")));
    inputs
        .iter()
        .all(|p| modified(p).is_some_and(|m| m <= built))
}

fn modified(path: &Path) -> Option<std::time::SystemTime> {
    std::fs::metadata(path).and_then(|m| m.modified()).ok()
}

/// The paths of a make-style dependency list (`\ ` is a space inside a path).
fn split_dep_info(deps: &str) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut current = String::new();
    let mut chars = deps.trim().chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '\\' if chars.peek().is_some_and(|n| *n == ' ' || *n == '\\') => {
                current.push(chars.next().unwrap_or(' '));
            }
            c if c.is_whitespace() => {
                if !current.is_empty() {
                    out.push(PathBuf::from(std::mem::take(&mut current)));
                }
            }
            c => current.push(c),
        }
    }
    if !current.is_empty() {
        out.push(PathBuf::from(current));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runners_build_in_the_target_folder_of_the_library_s_workspace() {
        let root = std::env::temp_dir().join(format!("ferroc-target-{}", std::process::id()));
        let member = root.join("crates/beep");
        std::fs::create_dir_all(&member).unwrap();
        std::fs::write(
            root.join("Cargo.toml"),
            "[workspace]\nmembers = [\"crates/*\"]\n",
        )
        .unwrap();
        std::fs::write(member.join("Cargo.toml"), "[package]\nname = \"beep\"\n").unwrap();
        assert_eq!(target_dir_from(None, &member), root.join("target"));
        // A crate of its own (no workspace above declares it).
        std::fs::write(root.join("Cargo.toml"), "[package]\nname = \"top\"\n").unwrap();
        assert_eq!(target_dir_from(None, &member), member.join("target"));
        // CARGO_TARGET_DIR wins, made absolute; empty counts as unset.
        let shared = root.join("shared");
        assert_eq!(
            target_dir_from(Some(shared.clone().into()), &member),
            shared
        );
        assert_eq!(
            target_dir_from(Some("".into()), &member),
            member.join("target")
        );
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn library_crates_are_taken_by_path_or_by_version() {
        let lib = |library: &str, package: &str, version: Option<&str>| LibraryCrate {
            library: library.into(),
            package: package.into(),
            dir: PathBuf::from(format!("/libs/{library}")),
            version: version.map(str::to_string),
            manifest_at: String::new(),
        };
        let toml = cargo_toml(
            "ferroc-runner-k",
            Kind::Inspect,
            Path::new("/ferroc/host"),
            &[
                lib("beep", "beep-lib", None),
                lib("arm", "my-arm", Some(">=0.3, <0.5")),
            ],
        );
        assert!(
            toml.contains("ferroc-host = { path = \"/ferroc/host\" }\n"),
            "{toml}"
        );
        assert!(
            toml.contains("library_0 = { package = \"beep-lib\", path = \"/libs/beep\" }\n"),
            "{toml}"
        );
        assert!(
            toml.contains("library_1 = { package = \"my-arm\", version = \">=0.3, <0.5\" }\n"),
            "{toml}"
        );
        // Another version is another runner.
        let key_of = |v| key(Path::new("/f"), &[lib("arm", "my-arm", Some(v))], "debug");
        assert_ne!(key_of("0.3"), key_of("0.4"));
    }

    #[test]
    fn dep_info_paths_keep_escaped_spaces() {
        assert_eq!(
            split_dep_info("/a/b.rs /c\\ d/e.rs\n"),
            vec![PathBuf::from("/a/b.rs"), PathBuf::from("/c d/e.rs")]
        );
    }
}
