//! The component libraries the parts use, each as the Cargo package a part depends on.

use std::collections::BTreeMap;

use super::super::text;
use super::{Library, Split};

impl<'p> Split<'_, 'p> {
    /// The libraries the parts use, by name, each with its Cargo package; every part's
    /// list sorted.
    pub(super) fn libraries(&mut self) -> BTreeMap<String, Library> {
        let mut libraries = BTreeMap::new();
        let mut parts = std::mem::take(&mut self.parts);
        for part in &mut parts {
            part.libraries.sort();
            for name in &part.libraries {
                if libraries.contains_key(name) {
                    continue;
                }
                if let Some(library) = self.library(name) {
                    libraries.insert(name.clone(), library);
                }
            }
        }
        self.parts = parts;
        libraries
    }

    /// The library `name` as a dependency: its `rust-crate` a Cargo package, maybe
    /// with a registry version. `None` for a library the set does not hold, and for
    /// one whose crate cannot be named (a problem).
    fn library(&mut self, name: &str) -> Option<Library> {
        let &id = self.libs.by_name.get(name)?;
        let lib = self.libs.get(id);
        let Some(rust_crate) = lib.rust_crate.clone() else {
            self.problem(lib.name_span, format!("the library `{name}` has no `rust-crate`: the bundle cannot depend on its module types\n  help: add rust-crate=\"cargo-package-name\" to its <library>"));
            return None;
        };
        let (package, registry) = match rust_crate.split_once('@') {
            Some((p, v)) => (p.to_owned(), Some(v.trim().to_owned())),
            None => (rust_crate, None),
        };
        if let Some(v) = registry
            .as_deref()
            .filter(|v| !crate::runner::crates::is_requirement(v))
        {
            self.problem(
                lib.name_span,
                format!(
                    "`{}` after the `@` of the rust-crate of library `{name}` is not a version\n  help: write e.g. rust-crate=\"{}@0.3\"",
                    text::comment(v),
                    text::comment(&package)
                ),
            );
            return None;
        }
        if !text::is_crate_name(&package) {
            self.problem(
                lib.name_span,
                format!(
                    "the rust-crate `{}` of library `{name}` is not a Cargo package name",
                    text::comment(&package)
                ),
            );
            return None;
        }
        Some(Library {
            name: name.to_owned(),
            package,
            version: lib.version.clone().filter(|v| text::is_version(v)),
            registry,
        })
    }
}
