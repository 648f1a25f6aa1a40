//! The features cargo resolves for each registry crate of a build, on each of its two
//! sides: what is compiled into the program (`Side::Target`) and what into its build
//! scripts and proc-macros (`Side::Host`; resolver 2 keeps their features apart). Read
//! from `cargo tree`'s indented output, which marks the host side by `[build-dependencies]`
//! headers and `(proc-macro)` crates: everything below either is compiled for the host.
//!
//! Cargo names a compiled crate by a hash of its features and of its dependencies'
//! hashes (and the profile, and the compiler). A runner reuses what
//! `cargo install --locked --path .` compiled only for crates whose features on the same
//! side agree with the install's (issue 26); `differences` says which do not.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::process::Command;

/// Which of a build's two feature resolutions a crate is compiled in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Side {
    /// Into the program.
    Target,
    /// Into a build script or proc-macro (run by the compiler on the build machine).
    Host,
}

impl Side {
    fn words(self) -> &'static str {
        match self {
            Side::Target => "in the program",
            Side::Host => "for build scripts and proc-macros",
        }
    }
}

/// (side, crate, version) → the features it is compiled with, comma-separated as cargo
/// prints them (sorted; empty for none). Crates of the workspace or from a path are
/// left out: cargo names those by their path relative to the workspace's root, so a
/// runner (its own workspace) compiles them again whatever their features.
pub type Resolve = BTreeMap<(Side, String, String), BTreeSet<String>>;

/// The resolve of a build of `package` (else every package) of `manifest`: its normal
/// and build dependencies, for this machine, as a build without tests sees them.
pub fn resolve(manifest: &Path, package: Option<&str>) -> Resolve {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut command = Command::new(cargo);
    command
        .args([
            "tree",
            "--offline",
            "-e",
            "normal,build",
            "--charset",
            "ascii",
        ])
        .args(["--format", "{p} {f}", "--manifest-path"])
        .arg(manifest);
    if let Some(p) = package {
        command.args(["-p", p]);
    }
    let out = command.output().expect("cargo runs");
    assert!(
        out.status.success(),
        "cargo tree of {} failed: {}",
        manifest.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    parse(&String::from_utf8_lossy(&out.stdout))
}

/// One line of `cargo tree --charset ascii --format "{p} {f}"`: its depth (the
/// connector's column / 4, a header's: the depth of the crates below it) and text.
fn split_line(line: &str) -> (usize, &str) {
    let text = line.trim_start_matches(['|', '`', '-', ' ']);
    let prefix = line.len() - text.len();
    if text.starts_with('[') {
        (prefix / 4 + 1, text)
    } else {
        (prefix / 4, text)
    }
}

/// The resolve `cargo tree` printed (see [`resolve`]).
pub fn parse(text: &str) -> Resolve {
    let mut out = Resolve::new();
    // The ancestors of the current line: (depth, whether it is on the host side). A
    // header counts as an ancestor of the crates below it, half a level up.
    let mut ancestors: Vec<(f32, bool)> = Vec::new();
    for line in text.lines() {
        let (depth, text) = split_line(line);
        if text.trim().is_empty() {
            ancestors.clear(); // the next root's tree
            continue;
        }
        let depth = depth as f32;
        if text.starts_with('[') {
            ancestors.retain(|(d, _)| *d < depth - 0.5);
            ancestors.push((depth - 0.5, text == "[build-dependencies]"));
            continue;
        }
        ancestors.retain(|(d, _)| *d < depth);
        let words: Vec<&str> = text
            .split_whitespace()
            .filter(|w| *w != "(*)" && *w != "(proc-macro)")
            .collect();
        let host = ancestors.iter().any(|(_, h)| *h) || text.contains("(proc-macro)");
        ancestors.push((depth, host));
        let [name, version, rest @ ..] = words.as_slice() else {
            continue;
        };
        if rest.first().is_some_and(|w| w.starts_with('(')) {
            continue; // a path crate: `name v0.1.0 (/path) features`
        }
        let side = if host { Side::Host } else { Side::Target };
        let features = rest.first().copied().unwrap_or("").to_string();
        out.entry((side, (*name).to_string(), (*version).to_string()))
            .or_default()
            .insert(features);
    }
    out
}

/// One message per crate `runner` compiles that the install (`install`) did not
/// compile alike: with other features on the same side, or not at all. Each says what
/// to write in the runner's manifest (`pins`, e.g. runner/Cargo.toml) to match.
pub fn differences(install: &Resolve, runner: &Resolve, pins: &str) -> Vec<String> {
    let mut out = Vec::new();
    for (key @ (side, name, version), features) in runner {
        let table = match side {
            Side::Target => "[dependencies]",
            Side::Host => "[build-dependencies]",
        };
        let at = format!("`{name} {version}` ({})", side.words());
        match install.get(key) {
            None => out.push(format!(
                "{at} is compiled for the runner but the install does not compile it (so the first run does)"
            )),
            Some(theirs) if theirs != features => out.push(format!(
                "{at}: the runner resolves the features `{}`, the install `{}`\n  \
                 help: in {pins}'s {table}: {}",
                listed(features),
                listed(theirs),
                pin_line(name, version, theirs)
            )),
            Some(_) => {}
        }
    }
    out
}

/// A feature set as cargo prints it, `none` for the empty one (more than one set, which
/// one resolve should not hold, joined by ` | `).
fn listed(sets: &BTreeSet<String>) -> String {
    let each: Vec<&str> = sets
        .iter()
        .map(|s| if s.is_empty() { "none" } else { s.as_str() })
        .collect();
    each.join(" | ")
}

/// The manifest line asking for `features` of this crate (the version requirement any
/// semver-compatible lock entry meets).
fn pin_line(name: &str, version: &str, features: &BTreeSet<String>) -> String {
    let v = version.trim_start_matches('v');
    let mut parts = v.split('.');
    let (major, minor) = (parts.next().unwrap_or("0"), parts.next().unwrap_or("0"));
    let requirement = match (major, minor) {
        ("0", "0") => format!("={v}"),
        ("0", minor) => format!("0.{minor}"),
        (major, _) => major.to_string(),
    };
    let all: BTreeSet<&str> = features
        .iter()
        .flat_map(|f| f.split(','))
        .filter(|f| !f.is_empty())
        .collect();
    let names: Vec<String> = all
        .iter()
        .filter(|f| **f != "default")
        .map(|f| format!("{f:?}"))
        .collect();
    let defaults = if all.contains("default") {
        ""
    } else {
        "default-features = false, "
    };
    format!(
        "{name} = {{ version = \"{requirement}\", {defaults}features = [{}] }}",
        names.join(", ")
    )
}
