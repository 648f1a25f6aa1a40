//! The crates a bundle depends on: the runtime, inspection and Zenoh where parts need
//! them, the libraries' crates (by path or version), found and checked before anything
//! is written.

use super::files::{Dependency, Source};
use super::names::relative;
use super::{layout, BundleArgs, Deps, TOOL_VERSION};
use crate::runner::checkout;
use crate::runner::crates::{self, LibraryCrate};
use std::path::{Path, PathBuf};

/// The Cargo package of the standard library, whose recorders every program has.
pub(super) const STD_PACKAGE: &str = "ferroc-std";

/// The runtime and the component crates the parts use, by path or by version.
pub(super) fn dependencies(
    layout: &layout::Layout<'_>,
    args: &BundleArgs,
    root: &Path,
    found: &PathCrates,
) -> Result<Vec<Dependency>, String> {
    let deps = args.deps;
    let checkout = sources();
    let ours = |package: &str, folder: &str, what: &str| -> Result<Dependency, String> {
        Ok(Dependency {
            package: package.into(),
            source: match deps {
                Deps::Path => by_path(root, checkout.join(folder), what)?,
                Deps::Version => Source::Version(TOOL_VERSION.into()),
            },
            features: None,
        })
    };
    let mut out = vec![ours("ferroc-runtime", "runtime", "the runtime")?];
    // Programs that serve inspection on request (`--inspect`, docs/inspect.md).
    if layout.parts.iter().any(|p| p.is_inspected(args.inspect)) {
        out.push(ours("ferroc-inspect", "inspect", "the inspection server")?);
    }
    // Programs of linked parts and of ROS 2 nodes talk over Zenoh (only when some
    // part needs it).
    if layout.parts.iter().any(|p| p.uses_zenoh()) {
        let mut zenoh = ours("ferroc-zenoh", "zenoh-link", "the Zenoh transport")?;
        let ros2 = layout.parts.iter().any(|p| p.ros2.is_some());
        zenoh.features = Some(match (shares_memory(layout), ros2) {
            (true, true) => &["shared-memory", "ros2-durability"],
            (true, false) => &["shared-memory"],
            (false, true) => &["ros2-durability"],
            (false, false) => &[],
        });
        out.push(zenoh);
    }
    for lib in layout.libraries.values() {
        out.push(Dependency {
            package: lib.package.clone(),
            source: library_source(lib, deps, root, found)?,
            features: None,
        });
    }
    // Every program can record (`--record`) with the standard library's recorders.
    if !out.iter().any(|d| d.package == STD_PACKAGE) {
        let folder = format!("components/{STD_PACKAGE}");
        out.push(ours(STD_PACKAGE, &folder, "the standard library")?);
    }
    Ok(out)
}

/// Whether a program of the bundle may use shared memory (ferroc-zenoh's feature
/// `shared-memory`, Zenoh's shared memory and 21 crates): where two parts speaking Zenoh
/// run on the same host (`<part host>`, `localhost` when not given) and not both have
/// `shared-memory="off"`, or a ROS 2 node's part has not turned it off (its peers on
/// the same computer may offer it). Parts on different computers never share memory.
pub(super) fn shares_memory(layout: &layout::Layout<'_>) -> bool {
    let on = |p: &layout::Part<'_>| p.shared_memory.enabled != Some(false);
    let speaking: Vec<&layout::Part<'_>> = layout.parts.iter().filter(|p| p.uses_zenoh()).collect();
    let ros2 = speaking.iter().any(|p| p.ros2.is_some() && on(p));
    let same_host = speaking.iter().enumerate().any(|(i, a)| {
        speaking[i + 1..]
            .iter()
            .any(|b| a.host == b.host && (on(a) || on(b)))
    });
    ros2 || same_host
}

/// The crate in folder `dir` as a path relative to the bundle's `root` (absolute when
/// they share only `/`).
fn by_path(root: &Path, dir: PathBuf, what: &str) -> Result<Source, String> {
    let dir = dir.canonicalize().map_err(|_| {
        format!(
            "{what}: no crate at {}; build ferroc from a checkout, or use --deps version",
            dir.display()
        )
    })?;
    Ok(Source::Path(
        relative(root, &dir).unwrap_or_else(|| dir.to_string_lossy().into_owned()),
    ))
}

/// Where a library's crate comes from: the registry for `rust-crate="PACKAGE@VERSION"`
/// whatever `--deps` says; else by its version, or by path where `found` has it.
fn library_source(
    lib: &layout::Library,
    deps: Deps,
    root: &Path,
    found: &PathCrates,
) -> Result<Source, String> {
    if let Some(version) = &lib.registry {
        return Ok(Source::Version(version.clone()));
    }
    match deps {
        Deps::Version => Ok(Source::Version(lib.version.clone().ok_or_else(|| {
            format!("the library `{}` declares no version: --deps version needs <library version=\"x.y.z\">", lib.name)
        })?)),
        Deps::Path => {
            let c = found.get(&lib.name).ok_or_else(|| {
                format!("the crate of library `{}` was not looked for", lib.name)
            })?;
            by_path(root, c.dir.clone(), &lib.name)
        }
    }
}

/// The crates of the libraries taken by path, by library name.
pub(super) type PathCrates = std::collections::BTreeMap<String, LibraryCrate>;

/// With `--deps path`, the crates of the parts' libraries not named by version, found
/// as `ferroc run` finds them (`runner::crates`: the manifest's folder, a folder named
/// after the package next to it, or ferroc's components); one message per library
/// whose crate is not found.
pub(super) fn path_crates(
    layout: &layout::Layout<'_>,
    result: &ferroc_compiler::CheckResult,
    deps: Deps,
) -> Result<PathCrates, Vec<String>> {
    let libs = &result.libraries;
    let mut found = PathCrates::new();
    let mut problems = Vec::new();
    let by_path = layout.libraries.values().filter(|l| l.registry.is_none());
    for lib in by_path.filter(|_| deps == Deps::Path) {
        let Some(&id) = libs.by_name.get(&lib.name) else {
            continue;
        };
        match crates::find(libs.get(id), &result.sources) {
            Ok(c) => {
                found.insert(lib.name.clone(), c);
            }
            Err(e) => problems.push(e),
        }
    }
    if problems.is_empty() {
        Ok(found)
    } else {
        Err(problems)
    }
}

/// ferroc's sources, whose runtime and components a bundle depends on by path: as for
/// `ferroc run`, `FERROC_SOURCE` if set, else the checkout this ferroc was built from.
pub(super) fn sources() -> PathBuf {
    crate::runner::source_dir()
}

/// One message per crate of `found` that depends on another `ferroc-runtime` than the
/// bundle's (another checkout's, or the registry's): cargo would stop with "package
/// collision in the lockfile", which says neither what is wrong nor what to do
/// (`runner::checkout`, shared with `ferroc run`).
pub(super) fn one_runtime(found: &PathCrates) -> Vec<String> {
    let crates: Vec<LibraryCrate> = found.values().cloned().collect();
    let runtime = sources().join("runtime");
    let runtime = runtime.canonicalize().unwrap_or(runtime);
    checkout::conflicts(&crates, &runtime, checkout::Linker::Bundle)
}
