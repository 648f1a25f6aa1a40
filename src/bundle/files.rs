//! The files around the generated code: Cargo manifests, `manifest.json`, a launch
//! script per host and a systemd unit per part. The manifests, scripts and units come
//! from the templates in `templates/` (askama; `askama.toml` says how each file type
//! escapes what is interpolated); `manifest.json` is written by serde_json.

use super::escape::filters;
use super::layout::Layout;
use askama::Template;
use std::collections::BTreeMap;

/// How a generated crate finds a dependency.
pub enum Source {
    /// `path = "…"` (relative to the bundle folder, or absolute).
    Path(String),
    /// `version = "…"` from a registry.
    Version(String),
}

/// A dependency of the generated crates: Cargo package name and where it comes from.
pub struct Dependency {
    pub package: String,
    pub source: Source,
    /// `None`: the crate's default features; `Some(list)`: only these
    /// (`default-features = false`).
    pub features: Option<&'static [&'static str]>,
}

impl Dependency {
    /// What follows the source in the workspace's `[workspace.dependencies]` line:
    /// nothing, or `, default-features = false` and the features asked for (names of
    /// ours, never the model's).
    pub fn toml_features(&self) -> String {
        match self.features {
            None => String::new(),
            Some([]) => ", default-features = false".into(),
            Some(list) => {
                let list: Vec<String> = list.iter().map(|f| format!("\"{f}\"")).collect();
                format!(
                    ", default-features = false, features = [{}]",
                    list.join(", ")
                )
            }
        }
    }
}

/// The workspace `Cargo.toml` (template `workspace.toml`; ctrlc stops the programs on
/// Ctrl-C and SIGTERM, as in `ferroc run`).
#[derive(Template)]
#[template(path = "workspace.toml")]
struct WorkspaceToml<'a> {
    tool_version: &'a str,
    application: &'a str,
    parts: Vec<&'a str>,
    deps: &'a [Dependency],
    /// ferroc's `[profile.*]` tables (`runner::program::profiles_for`).
    profiles: String,
}

/// The `Cargo.toml` of one part's package (template `part.toml`).
#[derive(Template)]
#[template(path = "part.toml")]
struct PartToml<'a> {
    tool_version: &'a str,
    application: &'a str,
    part: &'a str,
    package: &'a str,
    deps: &'a [&'a Dependency],
}

/// The workspace `Cargo.toml` at the root of the bundle.
pub fn workspace_toml(layout: &Layout<'_>, deps: &[Dependency], tool_version: &str) -> String {
    WorkspaceToml {
        tool_version,
        application: &layout.application,
        parts: layout.parts.iter().map(|p| p.name.as_str()).collect(),
        deps,
        profiles: bundle_profiles(deps),
    }
    .to_string()
}

/// ferroc's own `[profile.*]` tables, so that a bundle compiles every crate as the
/// install and the runners do. The tables of single crates are Zenoh's (held by
/// tests/runner_crates.rs): kept only when a program links Zenoh (`ferroc-zenoh` or
/// `ferroc-inspect`), else cargo would warn that they match nothing.
fn bundle_profiles(deps: &[Dependency]) -> String {
    let zenoh = (deps.iter()).any(|d| d.package == "ferroc-zenoh" || d.package == "ferroc-inspect");
    let manifest = crate::runner::program::workspace_manifest();
    crate::runner::program::profiles_for(&manifest, zenoh)
        .trim()
        .to_string()
}

/// The `Cargo.toml` of one part's package.
pub fn part_toml(
    layout: &Layout<'_>,
    part: usize,
    deps: &[&Dependency],
    tool_version: &str,
) -> String {
    let p = &layout.parts[part];
    PartToml {
        tool_version,
        application: &layout.application,
        part: &p.name,
        package: &p.package,
        deps,
    }
    .to_string()
}

/// `manifest.json`: what was bundled from what, and how each part is started.
pub struct ManifestInput<'a> {
    pub tool_version: &'a str,
    pub model_file: &'a str,
    pub model_sha256: String,
    /// Every file the check read (model, includes, config files, manifests): name, hash.
    pub sources: Vec<(String, String)>,
    pub deps: &'a [Dependency],
    pub files: Vec<String>,
}

pub fn manifest_json(layout: &Layout<'_>, m: &ManifestInput<'_>) -> String {
    use serde_json::{json, Value};
    let parts: Vec<Value> = layout
        .parts
        .iter()
        .map(|p| {
            json!({
                "name": p.name,
                "host": p.host,
                "address": p.address,
                "links_out": p.links_out.len(),
                "links_in": p.links_in.len(),
                "package": p.package,
                "binary": format!("target/release/{}", p.package),
                "command": [format!("target/release/{}", p.package), "--quiet"],
                "systemd_unit": format!("systemd/{}.service", p.package),
                "modules": p.modules.iter().map(|m| json!({"path": m.path, "type": m.type_name, "rust": m.rust})).collect::<Vec<_>>(),
                "thread_containers": p.threads.iter().map(|t| t.path.clone()).collect::<Vec<_>>(),
                "libraries": p.libraries,
            })
        })
        .collect();
    let mut hosts: BTreeMap<&str, Vec<&str>> = BTreeMap::new();
    for p in &layout.parts {
        hosts
            .entry(p.host.as_str())
            .or_default()
            .push(p.name.as_str());
    }
    let hosts: Vec<Value> = hosts
        .iter()
        .map(|(h, parts)| json!({"name": h, "parts": parts, "launch": format!("launch/{h}.sh")}))
        .collect();
    let deps: Vec<Value> = m
        .deps
        .iter()
        .map(|d| match &d.source {
            Source::Path(p) => json!({"package": d.package, "path": p}),
            Source::Version(v) => json!({"package": d.package, "version": v}),
        })
        .collect();
    let doc = json!({
        "format": "ferroc-bundle/1",
        "tool": {"name": "ferroc", "version": m.tool_version},
        "application": layout.application,
        "model": {
            "file": m.model_file,
            "sha256": m.model_sha256,
            "resolved": format!("model/{}.xml", layout.application),
            "sources": m.sources.iter().map(|(f, h)| json!({"file": f, "sha256": h})).collect::<Vec<_>>(),
        },
        "parts": parts,
        "hosts": hosts,
        "binaries": layout.parts.iter().map(|p| format!("target/release/{}", p.package)).collect::<Vec<_>>(),
        "dependencies": deps,
        "files": m.files,
    });
    let mut s = serde_json::to_string_pretty(&doc).unwrap_or_default();
    s.push('\n');
    s
}

/// `launch/HOST.sh` (template `launch.sh`).
#[derive(Template)]
#[template(path = "launch.sh")]
struct LaunchScript<'a> {
    tool_version: &'a str,
    application: &'a str,
    host: &'a str,
    /// (part, package) of each part on the host.
    parts: Vec<(&'a str, &'a str)>,
}

/// `systemd/PACKAGE.service` (template `unit.service`).
#[derive(Template)]
#[template(path = "unit.service")]
struct SystemdUnit<'a> {
    tool_version: &'a str,
    application: &'a str,
    part: &'a str,
    package: &'a str,
    prefix: &'a str,
}

/// `launch/HOST.sh`: starts every part of one host and stops them together.
pub fn launch_script(layout: &Layout<'_>, host: &str, tool_version: &str) -> String {
    LaunchScript {
        tool_version,
        application: &layout.application,
        host,
        parts: (layout.parts.iter())
            .filter(|p| p.host == host)
            .map(|p| (p.name.as_str(), p.package.as_str()))
            .collect(),
    }
    .to_string()
}

/// `systemd/PACKAGE.service` for one part, its binary installed under `prefix/bin`.
pub fn systemd_unit(layout: &Layout<'_>, part: usize, prefix: &str, tool_version: &str) -> String {
    let p = &layout.parts[part];
    SystemdUnit {
        tool_version,
        application: &layout.application,
        part: &p.name,
        package: &p.package,
        prefix,
    }
    .to_string()
}

/// An install prefix for systemd units: an absolute path of plain components.
pub fn valid_prefix(prefix: &str) -> bool {
    prefix.starts_with('/') && (prefix == "/" || super::out::safe_relative(&prefix[1..]).is_ok())
}
