//! Which Rust crate implements a library: the manifest's `rust-crate`, found by path.

use ferroc_compiler::library::{Library, LibrarySet};
use ferroc_compiler::source::SourceMap;
use std::path::{Path, PathBuf};

/// A library the runner links: its crate and where its manifest is (for messages).
#[derive(Clone, Debug)]
pub struct LibraryCrate {
    pub library: String,
    /// The Cargo package name (`rust-crate=`).
    pub package: String,
    /// The crate's folder (holding its Cargo.toml), canonical.
    pub dir: PathBuf,
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
    let at = ferroc_host::run::at(sources, lib.name_span);
    let Some(package) = lib.rust_crate.clone() else {
        return Err(format!(
            "{at}: error: the library `{}` has no `rust-crate`: ferroc cannot find the Rust code of its module types\n  \
             help: add rust-crate=\"PACKAGE\" to its <library>, naming the Cargo package (next to this manifest) whose `register` function registers them",
            lib.name
        ));
    };
    if !crate::bundle::text::is_crate_name(&package) {
        return Err(format!(
            "{at}: error: the rust-crate `{}` of library `{}` is not a Cargo package name\n  \
             help: a package name is letters, digits, `-` and `_`, e.g. rust-crate=\"my-robot\"",
            crate::bundle::text::comment(&package),
            lib.name
        ));
    }
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
    let candidates = [
        manifest_dir.to_path_buf(),
        manifest_dir.join(&package),
        crate::runner::program::source_dir()
            .join("components")
            .join(&package),
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
         help: put the crate next to the manifest (`ferroc new library` writes one), or correct rust-crate=",
        lib.name,
        looked.join(", "),
        if others.is_empty() {
            String::new()
        } else {
            format!("; found other packages: {}", others.join(", "))
        }
    ))
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
    use super::package_name;

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
