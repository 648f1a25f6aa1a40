//! One `ferroc-runtime` per program: a runner links the host crate of ferroc's sources,
//! and with it their `ferroc-runtime`; a bundle's parts depend on that same runtime
//! (`ferroc bundle --deps path`). A library crate depending on another copy (a path
//! into another checkout, or a version from a registry) cannot be linked with it: cargo
//! would stop with a lockfile collision ("package collision in the lockfile") or with
//! type errors between the two copies. Found before building, from `cargo metadata
//! --no-deps` of each library crate, and reported at the manifest with both places and
//! the fixes.

use super::crates::LibraryCrate;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// Where a library crate takes `ferroc-runtime` from, if not from `runtime`.
#[derive(Clone, Debug, PartialEq)]
pub enum Other {
    /// A path dependency on another folder.
    Path(PathBuf),
    /// From a registry, with this requirement.
    Registry(String),
}

/// What links the library crates with ferroc's runtime: named in the message, with
/// its own way of using the other checkout instead.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Linker {
    /// `ferroc run`'s runner.
    Runner,
    /// The programs of `ferroc bundle`.
    Bundle,
}

/// One message per library crate whose `ferroc-runtime` is not `runtime` (the folder
/// of ferroc's own, canonical). Crates cargo cannot describe are left to the build.
pub fn conflicts(crates: &[LibraryCrate], runtime: &Path, linker: Linker) -> Vec<String> {
    let mut out = Vec::new();
    for c in crates.iter().filter(|c| c.version.is_none()) {
        let Some(metadata) = metadata(&c.dir) else {
            continue;
        };
        if let Some(other) = other_runtime(&metadata, &c.package, runtime) {
            out.push(message(c, &other, runtime, linker));
        }
    }
    out
}

/// `cargo metadata --no-deps` of the crate in `dir` (no resolution, no network).
fn metadata(dir: &Path) -> Option<serde_json::Value> {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let output = Command::new(cargo)
        .args([
            "metadata",
            "--no-deps",
            "--format-version",
            "1",
            "--offline",
        ])
        .arg("--manifest-path")
        .arg(dir.join("Cargo.toml"))
        .stdin(Stdio::null())
        .stderr(Stdio::null())
        .output()
        .ok()?;
    if !output.status.success() {
        return None;
    }
    serde_json::from_slice(&output.stdout).ok()
}

/// The `ferroc-runtime` dependency of `package` in `metadata`, if it is not `runtime`.
pub fn other_runtime(metadata: &serde_json::Value, package: &str, runtime: &Path) -> Option<Other> {
    let packages = metadata.get("packages")?.as_array()?;
    let p = packages
        .iter()
        .find(|p| p.get("name").and_then(|n| n.as_str()) == Some(package))?;
    let dep = p
        .get("dependencies")?
        .as_array()?
        .iter()
        .find(|d| d.get("name").and_then(|n| n.as_str()) == Some("ferroc-runtime"))?;
    if let Some(path) = dep.get("path").and_then(|p| p.as_str()) {
        let path = PathBuf::from(path);
        let canonical = path.canonicalize().unwrap_or(path);
        return (canonical != runtime).then_some(Other::Path(canonical));
    }
    let req = dep.get("req").and_then(|r| r.as_str()).unwrap_or("*");
    Some(Other::Registry(req.to_owned()))
}

fn message(c: &LibraryCrate, other: &Other, runtime: &Path, linker: Linker) -> String {
    let theirs = match other {
        Other::Path(path) => format!("the ferroc-runtime at {}", path.display()),
        Other::Registry(req) => format!("ferroc-runtime {req} from the registry"),
    };
    let checkout = match other {
        Other::Path(path) => path
            .parent()
            .filter(|p| p.join("host/Cargo.toml").is_file()),
        Other::Registry(_) => None,
    };
    let who = match linker {
        Linker::Runner => "the runner links",
        Linker::Bundle => "the bundle's programs link",
    };
    let mut text = format!(
        "{}: error: the crate `{}` of library `{}` depends on {theirs}, but {who} the ferroc-runtime of this ferroc's sources, {}: one program cannot link both\n  \
         = crate: {}\n  \
         help: in {}, depend on ferroc's: ferroc-runtime = {{ path = \"{}\" }}",
        c.manifest_at,
        c.package,
        c.library,
        runtime.display(),
        c.dir.display(),
        c.dir.join("Cargo.toml").display(),
        runtime.display()
    );
    if let Some(checkout) = checkout {
        let help = match linker {
            Linker::Runner => "or run the ferroc of that checkout (`cargo install --path {0}`), or build the runner from its sources: FERROC_SOURCE={0}",
            Linker::Bundle => "or bundle with the ferroc of that checkout (`cargo install --path {0}`), or make the bundle depend on its sources: FERROC_SOURCE={0} ferroc bundle …",
        };
        text.push_str("\n  help: ");
        text.push_str(&help.replace("{0}", &checkout.display().to_string()));
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    fn metadata(dep: serde_json::Value) -> serde_json::Value {
        serde_json::json!({"packages": [
            {"name": "other", "dependencies": []},
            {"name": "beep", "dependencies": [{"name": "serde", "req": "^1"}, dep]},
        ]})
    }

    #[test]
    fn another_copy_of_the_runtime_is_found_by_path_or_registry() {
        let ours = std::env::temp_dir();
        let ours = ours.canonicalize().unwrap();
        let same =
            metadata(serde_json::json!({"name": "ferroc-runtime", "req": "*", "path": ours}));
        assert_eq!(other_runtime(&same, "beep", &ours), None);
        let elsewhere = metadata(
            serde_json::json!({"name": "ferroc-runtime", "req": "*", "path": "/nowhere/runtime"}),
        );
        assert_eq!(
            other_runtime(&elsewhere, "beep", &ours),
            Some(Other::Path("/nowhere/runtime".into()))
        );
        let registry = metadata(serde_json::json!({"name": "ferroc-runtime", "req": "^0.1"}));
        assert_eq!(
            other_runtime(&registry, "beep", &ours),
            Some(Other::Registry("^0.1".into()))
        );
        assert_eq!(
            other_runtime(&registry, "other", &ours),
            None,
            "no runtime dependency"
        );
    }
}
