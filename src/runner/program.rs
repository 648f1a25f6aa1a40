//! The runner program of a set of libraries: generated once, built by cargo in the
//! runner cache (`cache.rs`), rebuilt only when one of its sources changed.
//!
//! The package lives in `CACHE/ferroc-runner/KEY/` (KEY: a hash of the libraries'
//! crates, ferroc's sources and the profile), its binary `ferroc-runner-KEY` in
//! `CACHE/PROFILE/`: runners of different libraries never replace each other's files,
//! and share every compiled dependency. A model is not part of the runner: the runner
//! checks and plans the model it is given, so editing a model never rebuilds anything.
//!
//! Kinds of runner per set of libraries ([`Kind`]), each its own package with one
//! feature set, sharing the cache: the plain runner links `ferroc-runner` (the runtime,
//! the standard library, no compiler, no Zenoh) and is handed the plan of the model;
//! the inspecting runner (`ferroc run --inspect`) links `ferroc-host` with the compiler
//! and the inspection server; for a model whose parts are ROS 2 nodes, each also
//! links `ferroc-zenoh`, which opens the nodes.

use super::build::{self, Build};
use super::cache::{self, Cache};
use super::crates::LibraryCrate;
use super::failure::report_failure;
use super::source_dir;
use crate::bundle::text::{comment, toml_str};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// The cargo profile runners are built with: ferroc's own (a release ferroc runs
/// release runners).
fn profile() -> &'static str {
    if cfg!(debug_assertions) {
        "debug"
    } else {
        "release"
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
    /// `ferroc run` of a model whose parts are ROS 2 nodes: `ferroc-runner` and
    /// `ferroc-zenoh`, which opens the nodes (docs/ros2.md); still no compiler.
    Ros2,
    /// `ferroc run --inspect` of a model whose parts are ROS 2 nodes: the inspecting
    /// runner with `ferroc-zenoh` opening the nodes (on a session of their own, beside
    /// the inspection server's).
    InspectRos2,
}

impl Kind {
    /// The workspace crate the runner depends on: its folder and package name.
    fn host_crate(self) -> (&'static str, &'static str) {
        match self {
            Kind::Plain | Kind::Ros2 => ("runner", "ferroc-runner"),
            Kind::Inspect | Kind::InspectRos2 => ("host", "ferroc-host"),
        }
    }

    /// Workspace crates the runner depends on besides the host crate: folder and
    /// package name.
    fn more_crates(self) -> &'static [(&'static str, &'static str)] {
        match self {
            Kind::Ros2 | Kind::InspectRos2 => &[("zenoh-link", "ferroc-zenoh")],
            Kind::Plain | Kind::Inspect => &[],
        }
    }

    /// Its name in the runner's key and messages.
    fn name(self) -> &'static str {
        match self {
            Kind::Plain => "plain",
            Kind::Inspect => "inspect",
            Kind::Ros2 => "ros2",
            Kind::InspectRos2 => "inspect-ros2",
        }
    }
}

/// A built runner of this kind for `crates`: its executable, built now if needed (one
/// line of progress; cargo's own output with `verbose`). On failure the cause is
/// reported, pointing at the manifests.
pub fn ensure(crates: &[LibraryCrate], kind: Kind, verbose: bool) -> Result<PathBuf, ExitCode> {
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
    let profile = profile();
    let key = key(&source, crates, &format!("{profile} {}", kind.name()));
    let cache = cache::locate();
    let name = format!("ferroc-runner-{key}");
    let dir = cache.dir.join(cache::PACKAGES).join(&key);
    let exe = build::executable(&cache.dir, profile, &name);
    let written = cache
        .prepare()
        .and_then(|()| write_all(&dir, &name, kind, &host, crates, &source, &cache));
    if let Err(message) = written {
        eprintln!("{message}");
        return Err(ExitCode::from(2));
    }
    let changed = match stale_input(&exe, &dir, crates, kind) {
        Ok(()) => return Ok(exe),
        Err(changed) => changed,
    };
    // Before cargo: a crate linking another ferroc-runtime would fail with cargo's
    // lockfile collision, which does not say what to do.
    let runtime = source.join("runtime");
    let conflicts = super::checkout::conflicts(
        crates,
        &runtime.canonicalize().unwrap_or(runtime),
        super::checkout::Linker::Runner,
    );
    if !conflicts.is_empty() {
        for c in &conflicts {
            eprintln!("{c}");
        }
        return Err(ExitCode::from(1));
    }
    let build_kind = build::kind(&exe, &cache.dir, profile);
    let why = build::why(build_kind, changed.as_deref(), crates, &source, &dir);
    let b = Build {
        crates,
        package: &dir,
        target: &cache.dir,
        profile,
        kind: build_kind,
        why,
        verbose,
    };
    let outcome = match build::build(&b) {
        Ok(o) => o,
        Err(e) => {
            eprintln!("error: cannot start cargo to build the runner: {e}\n  help: install Rust (rustup.rs) or set CARGO to cargo's path");
            return Err(ExitCode::from(2));
        }
    };
    if outcome.success && exe.is_file() {
        return Ok(exe);
    }
    if let Some(line) = outcome.full.or_else(|| cache.full_now()) {
        eprintln!(
            "{}",
            cache.unusable_because(std::io::ErrorKind::StorageFull, &line)
        );
        return Err(ExitCode::from(2));
    }
    report_failure(crates, &outcome.failed, &outcome.unavailable, &name, &dir);
    Err(ExitCode::from(1))
}

/// The runner's package in `dir` and its lock file; a message naming the cache when
/// they cannot be written there.
fn write_all(
    dir: &Path,
    name: &str,
    kind: Kind,
    host: &Path,
    crates: &[LibraryCrate],
    source: &Path,
    cache: &Cache,
) -> Result<(), String> {
    // What `ferroc cache` lists for this runner.
    let libraries: Vec<String> = crates
        .iter()
        .map(|c| format!("{} ({})", c.library, c.dir.display()))
        .collect();
    let listed = format!("{}; {} runner", libraries.join(", "), kind.name());
    write_package(dir, name, kind, host, crates)
        .and_then(|()| seed_lock(dir, source))
        .and_then(|()| replace_if_changed(&dir.join("libraries.txt"), listed.as_bytes()))
        .map_err(|e| cache.unusable(&e))
}

/// The runner's Cargo.lock starts as a copy of the checkout's, the versions ferroc is
/// built, tested and installed with (`cargo install --locked`), so that what the
/// install compiled is reused; cargo adds the libraries' own. When the checkout's lock
/// changes (a pull), the copy is made again rather than left to diverge.
fn seed_lock(dir: &Path, source: &Path) -> std::io::Result<()> {
    let Ok(text) = std::fs::read(source.join("Cargo.lock")) else {
        return Ok(());
    };
    let seed = crate::bundle::sha256::hex(&text);
    let seed_file = dir.join("Cargo.lock.seed");
    let lock = dir.join("Cargo.lock");
    let same = std::fs::read_to_string(&seed_file).is_ok_and(|s| s.trim() == seed);
    if same && lock.is_file() {
        return Ok(());
    }
    replace_if_changed(&lock, &text)?;
    replace_if_changed(&seed_file, seed.as_bytes())
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

/// Writes the runner's Cargo.toml and main.rs, each only when its text changes, through
/// a rename (runs started together write the same files; an interrupted run leaves the
/// old file or the new one, never half of one).
fn write_package(
    dir: &Path,
    name: &str,
    kind: Kind,
    host: &Path,
    crates: &[LibraryCrate],
) -> std::io::Result<()> {
    std::fs::create_dir_all(dir.join("src"))?;
    let toml = cargo_toml(name, kind, host, crates);
    let main = main_rs(kind, crates);
    replace_if_changed(&dir.join("Cargo.toml"), toml.as_bytes())?;
    replace_if_changed(&dir.join("src/main.rs"), main.as_bytes())
}

/// The runner's main.rs: the registry of the standard library's types and the
/// libraries', handed to the kind's `main`.
fn main_rs(kind: Kind, crates: &[LibraryCrate]) -> String {
    let version = env!("CARGO_PKG_VERSION");
    let (what, krate, registry, call) = match kind {
        Kind::Plain => (
            "runs the plans `ferroc run` hands it and describes its module types",
            "ferroc_runner",
            "ferroc_runner::registry()",
            "ferroc_runner::main(registry)",
        ),
        Kind::Inspect => (
            "runs `ferroc run --inspect`",
            "ferroc_host",
            "ferroc_host::run::registry()",
            "ferroc_host::main(registry)",
        ),
        Kind::Ros2 => (
            "runs the plans of models with ROS 2 nodes and describes its module types",
            "ferroc_runner",
            "ferroc_runner::registry()",
            "ferroc_runner::main_ros2(registry, ferroc_zenoh::ros2::network::network)",
        ),
        Kind::InspectRos2 => (
            "runs `ferroc run --inspect` of models with ROS 2 nodes",
            "ferroc_host",
            "ferroc_host::run::registry()",
            "ferroc_host::main_ros2(registry, ferroc_zenoh::ros2::network::network)",
        ),
    };
    let mut main = format!(
        "//! Generated by ferroc {version}: {what}, with the module\n\
         //! types of the standard library and of the libraries linked here.\n\n\
         /// The allocator ferroc itself uses (applications allocate as under ferroc).\n\
         #[global_allocator]\n\
         static GLOBAL: {krate}::mimalloc::MiMalloc = {krate}::mimalloc::MiMalloc;\n\n\
         fn main() -> std::process::ExitCode {{\n"
    );
    if kind.more_crates().iter().any(|(_, p)| *p == "ferroc-zenoh") {
        // Its ROS 2 nodes' session: Zenoh's runtime threads as a bundle's part program
        // has them (docs/zenoh.md "Zenoh's threads").
        main.push_str(
            "    // Zenoh's runtime threads: ferroc's unless ZENOH_RUNTIME is set; Zenoh reads the\n    \
             // variable once, so before any thread or session (docs/zenoh.md \"Zenoh's threads\").\n    \
             ferroc_zenoh::config::runtime::use_default();\n",
        );
    }
    main.push_str(&format!("    let mut registry = {registry};\n"));
    for (i, c) in crates.iter().enumerate() {
        main.push_str(&format!(
            "    // The library `{}`.\n    library_{i}::register(&mut registry);\n",
            comment(&c.library)
        ));
    }
    main.push_str(&format!("    {call}\n}}\n"));
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
         # ferroc rewrites this file; it is built in the runner cache (`ferroc cache`).\n\
         [package]\nname = \"{name}\"\nversion = \"0.0.0\"\nedition = \"2021\"\npublish = false\n\n\
         [dependencies]\n{} = {{ path = {} }}\n",
        env!("CARGO_PKG_VERSION"),
        libraries.join(", "),
        kind.host_crate().1,
        toml_str(&host.to_string_lossy())
    );
    let workspace = host.parent().unwrap_or(host);
    for (folder, package) in kind.more_crates() {
        let path = workspace.join(folder);
        toml.push_str(&format!(
            "{package} = {{ path = {} }}\n",
            toml_str(&path.to_string_lossy())
        ));
    }
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
    toml.push_str(&profiles(&workspace_manifest()));
    toml.push_str("\n# Not a member of any enclosing workspace.\n[workspace]\n");
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

/// `Ok` when `exe` is newer than everything it was built from: the source files cargo
/// listed in its dep-info (`exe.d`: every local crate's sources), the Cargo.toml of
/// the runner, of ferroc's host crate and of every library crate, and the lock file.
/// Else the first input found newer (`None`: no executable or dep-info), and the
/// decision is cargo's.
fn stale_input(
    exe: &Path,
    dir: &Path,
    crates: &[LibraryCrate],
    kind: Kind,
) -> Result<(), Option<PathBuf>> {
    let built = modified(exe).ok_or(None)?;
    let dep_info = std::fs::read_to_string(exe.with_extension("d")).map_err(|_| None)?;
    let (_, deps) = dep_info.split_once(": ").ok_or(None)?;
    let mut inputs: Vec<PathBuf> = split_dep_info(deps);
    if inputs.is_empty() {
        return Err(None);
    }
    inputs.push(dir.join("Cargo.toml"));
    inputs.push(dir.join("Cargo.lock"));
    inputs.push(source_dir().join("host/Cargo.toml"));
    inputs.push(source_dir().join("runner/Cargo.toml"));
    for (folder, _) in kind.more_crates() {
        inputs.push(source_dir().join(folder).join("Cargo.toml"));
    }
    // (A registry crate's sources are in cargo's cache, listed in the dep-info.)
    inputs
        .extend((crates.iter().filter(|c| c.version.is_none())).map(|c| c.dir.join("Cargo.toml")));
    match inputs
        .into_iter()
        .find(|p| modified(p).is_none_or(|m| m > built))
    {
        Some(changed) => Err(Some(changed)),
        None => Ok(()),
    }
}

/// ferroc's workspace manifest: the checkout's at run time (what `cargo install` there
/// uses), else the one ferroc was built from.
pub fn workspace_manifest() -> String {
    std::fs::read_to_string(source_dir().join("Cargo.toml"))
        .unwrap_or_else(|_| include_str!("../../Cargo.toml").to_string())
}

/// The `[profile.*]` tables of a manifest, as written (without comments and blank
/// lines, a blank line before each table): the runner takes the workspace's
/// so that both compile every shared crate alike and one reuses the other's output.
pub fn profiles(manifest: &str) -> String {
    profiles_for(manifest, true)
}

/// [`profiles`], without the tables of single crates (`[profile.*.package.NAME]`, not
/// `"*"`) unless `packages`: a build that does not link such a crate gets cargo's
/// warning that the table matches nothing.
pub fn profiles_for(manifest: &str, packages: bool) -> String {
    let mut out = String::new();
    let mut inside = false;
    for line in manifest.lines() {
        let trimmed = line.trim_start();
        if trimmed.starts_with('[') {
            let one_crate = trimmed.contains(".package.") && !trimmed.contains(".package.\"*\"]");
            inside = trimmed.starts_with("[profile.") && (packages || !one_crate);
            if inside {
                out.push('\n');
            }
        }
        if inside && !trimmed.starts_with('#') && !trimmed.is_empty() {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
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
    fn the_runner_is_built_with_the_workspace_s_profiles() {
        let workspace = include_str!("../../Cargo.toml");
        let ours = profiles(workspace);
        assert!(ours.contains("[profile.release]\n"), "{ours}");
        let toml = cargo_toml(
            "ferroc-runner-k",
            Kind::Plain,
            Path::new("/ferroc/runner"),
            &[],
        );
        assert_eq!(profiles(&toml), ours, "{toml}");
        // Only the profile tables are taken, comments left out.
        assert_eq!(
            profiles("[package]\nname = \"x\"\n[profile.release]\n# why\ndebug = 0\n[profile.dev.package.\"*\"]\nopt-level = 1\n\n[workspace]\n"),
            "\n[profile.release]\ndebug = 0\n\n[profile.dev.package.\"*\"]\nopt-level = 1\n"
        );
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

    /// A runner that opens ROS 2 nodes on Zenoh chooses Zenoh's runtime threads first,
    /// before the registry or any thread; the others do not link Zenoh's crate.
    #[test]
    fn runners_of_ros2_nodes_choose_zenoh_s_runtime_threads_first() {
        let call = "ferroc_zenoh::config::runtime::use_default();";
        for kind in [Kind::Ros2, Kind::InspectRos2] {
            let main = main_rs(kind, &[]);
            let body = main
                .split_once("fn main() -> std::process::ExitCode {\n")
                .unwrap()
                .1;
            let first = body.lines().find(|l| !l.trim_start().starts_with("//"));
            assert_eq!(first.map(str::trim), Some(call), "{main}");
        }
        for kind in [Kind::Plain, Kind::Inspect] {
            let main = main_rs(kind, &[]);
            assert!(!main.contains("ferroc_zenoh"), "{main}");
        }
    }

    #[test]
    fn dep_info_paths_keep_escaped_spaces() {
        assert_eq!(
            split_dep_info("/a/b.rs /c\\ d/e.rs\n"),
            vec![PathBuf::from("/a/b.rs"), PathBuf::from("/c d/e.rs")]
        );
    }
}
