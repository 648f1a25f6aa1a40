//! Which Rust crate implements a library: the manifest's `rust-crate`, found by path,
//! or `rust-crate="PACKAGE@VERSION"`: a package of that version from crates.io (or the
//! registry cargo is configured with), fetched by cargo when the runner is built.

use ferroc_compiler::library::{Library, LibrarySet};
use ferroc_compiler::source::SourceMap;
use std::path::{Path, PathBuf};

/// A library the runner links: its crate and where its manifest is (for messages).
#[derive(Clone, Debug)]
pub struct LibraryCrate {
    pub library: String,
    /// The Cargo package name (`rust-crate=`).
    pub package: String,
    /// The crate's folder (holding its Cargo.toml), canonical; for a crate from the
    /// registry the manifest's folder (where the runner's target folder is looked for).
    pub dir: PathBuf,
    /// `Some(requirement)`: the package comes from the registry in this version
    /// (`rust-crate="PACKAGE@VERSION"`), not from `dir`.
    pub version: Option<String>,
    /// `FILE:LINE:COL` of the manifest's `<library name=…>`.
    pub manifest_at: String,
}

/// The crates of `names` (libraries of `libs`, built-in ones skipped), or one message per
/// library whose crate cannot be found, each pointing at its manifest.
pub fn find_all<'a>(
    names: impl IntoIterator<Item = &'a str>,
    libs: &LibrarySet,
    sources: &SourceMap,
) -> Result<Vec<LibraryCrate>, Vec<String>> {
    let mut found = Vec::new();
    let mut problems = Vec::new();
    for name in names {
        let Some(&id) = libs.by_name.get(name) else {
            continue;
        };
        let lib = libs.get(id);
        if lib.path.as_os_str().is_empty() || lib.name == "ferroc_std" {
            continue; // built into ferroc (the standard library), its manifest or a copy
        }
        match find(lib, sources) {
            Ok(c) => found.push(c),
            Err(e) => problems.push(e),
        }
    }
    found.sort_by(|a, b| a.library.cmp(&b.library));
    if problems.is_empty() {
        Ok(found)
    } else {
        Err(problems)
    }
}

/// The crates a model needs linked: those of the libraries whose module types it
/// instantiates (each must be found), and of every other library it loads whose crate
/// is found (value types and field accessors they register; a library of data types
/// only whose crate is absent is left out, and a type it would register is reported
/// when the application is built).
pub fn needed_by_model(
    result: &ferroc_compiler::CheckResult,
) -> Result<Vec<LibraryCrate>, Vec<String>> {
    let libs = &result.libraries;
    let mut used = std::collections::BTreeSet::new();
    if let Some(app) = &result.app {
        for (_, m) in app.modules() {
            used.insert(libs.get(m.library).name.as_str());
        }
    }
    let mut found = find_all(used.iter().copied(), libs, &result.sources)?;
    for lib in &libs.libraries {
        if lib.rust_crate.is_some() && !used.contains(lib.name.as_str()) {
            if let Ok(mut c) = find_all([lib.name.as_str()], libs, &result.sources) {
                found.append(&mut c);
            }
        }
    }
    found.sort_by(|a, b| a.library.cmp(&b.library));
    Ok(found)
}

/// Where the crate of `lib` is: the manifest's folder itself when its Cargo.toml is that
/// package, a folder named after the package next to the manifest, or one in the
/// `components/` of the checkout ferroc was built from.
pub fn find(lib: &Library, sources: &SourceMap) -> Result<LibraryCrate, String> {
    let at = ferroc_host::sources::at(sources, lib.name_span);
    let (package, version) = package_and_version(lib, &at)?;
    let manifest_dir = lib
        .path
        .parent()
        .map(|d| {
            if d.as_os_str().is_empty() {
                Path::new(".")
            } else {
                d
            }
        })
        .unwrap_or(Path::new("."));
    if version.is_some() {
        // From the registry: nothing to find on disk; cargo fetches it when building.
        let dir = manifest_dir
            .canonicalize()
            .unwrap_or_else(|_| manifest_dir.to_path_buf());
        return Ok(LibraryCrate {
            library: lib.name.clone(),
            package,
            dir,
            version,
            manifest_at: at,
        });
    }
    find_on_disk(lib, package, manifest_dir, at)
}

/// The package of `lib`'s `rust-crate="PACKAGE"`, and the version requirement of
/// `"PACKAGE@VERSION"`; an error (at `at`) where either cannot be used.
fn package_and_version(lib: &Library, at: &str) -> Result<(String, Option<String>), String> {
    let Some(rust_crate) = lib.rust_crate.clone() else {
        return Err(format!(
            "{at}: error: the library `{}` has no `rust-crate`: ferroc cannot find the Rust code of its module types\n  \
             help: add rust-crate=\"PACKAGE\" to its <library>, naming the Cargo package (next to this manifest) whose `register` function registers them",
            lib.name
        ));
    };
    let (package, version) = match rust_crate.split_once('@') {
        Some((package, version)) => (package.to_owned(), Some(version.trim().to_owned())),
        None => (rust_crate, None),
    };
    if let Some(version) = version.as_deref().filter(|v| !is_requirement(v)) {
        return Err(format!(
            "{at}: error: `{}` after the `@` of rust-crate=\"{package}@…\" of library `{}` is not a version\n  \
             help: write a version (requirement) as in Cargo.toml, e.g. rust-crate=\"{package}@0.3\" or \"{package}@=0.3.1\"",
            crate::bundle::text::comment(version),
            lib.name
        ));
    }
    if !crate::bundle::text::is_crate_name(&package) {
        return Err(format!(
            "{at}: error: the rust-crate `{}` of library `{}` is not a Cargo package name\n  \
             help: a package name is letters, digits, `-` and `_`, e.g. rust-crate=\"my-robot\"",
            crate::bundle::text::comment(&package),
            lib.name
        ));
    }
    Ok((package, version))
}

/// The folder of `package` next to the manifest (in `manifest_dir`) or among the
/// checkout's components.
fn find_on_disk(
    lib: &Library,
    package: String,
    manifest_dir: &Path,
    at: String,
) -> Result<LibraryCrate, String> {
    let candidates = [
        manifest_dir.to_path_buf(),
        manifest_dir.join(&package),
        super::source_dir().join("components").join(&package),
    ];
    let mut others = Vec::new();
    for dir in &candidates {
        match package_name(&dir.join("Cargo.toml")) {
            Some(name) if name == package => {
                let dir = dir.canonicalize().unwrap_or_else(|_| dir.clone());
                return Ok(LibraryCrate {
                    library: lib.name.clone(),
                    package,
                    dir,
                    version: None,
                    manifest_at: at,
                });
            }
            Some(name) => others.push(format!("{} is `{name}`", dir.display())),
            None => {}
        }
    }
    let looked: Vec<String> = candidates
        .iter()
        .map(|c| c.join("Cargo.toml").display().to_string())
        .collect();
    Err(format!(
        "{at}: error: the crate `{package}` of library `{}` was not found\n  \
         = looked for a Cargo.toml with name = \"{package}\" at {}{}\n  \
         help: put the crate next to the manifest (`ferroc new library` writes one), correct rust-crate=, or name a published crate with rust-crate=\"{package}@VERSION\"",
        lib.name,
        looked.join(", "),
        if others.is_empty() {
            String::new()
        } else {
            format!("; found other packages: {}", others.join(", "))
        }
    ))
}

/// A version requirement as Cargo.toml takes it (`0.3`, `^1.2.3`, `=0.3.1`, `>=1, <2`,
/// `1.0.0-beta.2`): checked here so that it can be written into the runner's Cargo.toml
/// and a typo is reported at the manifest rather than by cargo.
pub fn is_requirement(v: &str) -> bool {
    !v.is_empty()
        && v.len() <= 64
        && v.split(',').all(|one| {
            let one = one
                .trim_start_matches(['=', '^', '~', '<', '>', ' '])
                .trim();
            one.starts_with(|c: char| c.is_ascii_digit() || c == '*')
        })
        && v.chars()
            .all(|c| c.is_ascii_alphanumeric() || ".^~=<>*,-+ ".contains(c))
}

/// The `[package] name` of a Cargo.toml, read line by line (no TOML parser needed for
/// one key; a manifest we cannot read this way is reported as not found).
pub fn package_name(cargo_toml: &Path) -> Option<String> {
    let text = std::fs::read_to_string(cargo_toml).ok()?;
    let mut in_package = false;
    for line in text.lines() {
        let line = line.trim();
        if line.starts_with('[') {
            in_package = line == "[package]";
            continue;
        }
        if !in_package {
            continue;
        }
        if let Some(rest) = line.strip_prefix("name") {
            let value = rest.trim_start().strip_prefix('=')?.trim();
            let value = value.split('#').next()?.trim();
            return Some(value.trim_matches(|c| c == '"' || c == '\'').to_string());
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::{is_requirement, package_name};

    #[test]
    fn version_requirements_as_cargo_takes_them() {
        for good in [
            "0.3",
            "^1.2.3",
            "=0.3.1",
            ">=1, <2",
            "1.0.0-beta.2",
            "*",
            "~0.4",
        ] {
            assert!(is_requirement(good), "{good}");
        }
        for bad in ["", "latest", "1.0\"", "x1", ">=", "1.0; rm", "0.1\n[patch]"] {
            assert!(!is_requirement(bad), "{bad}");
        }
    }

    #[test]
    fn the_package_name_is_read_from_the_package_table_only() {
        let dir = std::env::temp_dir().join(format!("ferroc-crates-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("Cargo.toml");
        let read = |text: &str| {
            std::fs::write(&file, text).unwrap();
            package_name(&file)
        };
        assert_eq!(
            read("[lib]\nname = \"beep\"\n\n[package]\nversion = \"1\"\nname = \"beep-lib\" # the crate\n"),
            Some("beep-lib".into())
        );
        assert_eq!(read("[workspace]\nmembers = [\"a\"]\n"), None);
        assert_eq!(read("[package]\nname.workspace = true\n"), None);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
