//! ferroc's model: everything from a model file's path to the resolved `Application`.
//!
//! * [`load`] — all file I/O: limits, includes, config files, standard input.
//! * [`library`] — library manifests to a `LibrarySet` (types, module types, group types).
//! * [`resolve`] — the element tree, module instances, paths and connections.
//! * [`ir`] — the `Application` every analysis and check reads.
//! * [`checks`] — the checks raised on the way (areas M, L, P).
//!
//! Depends on `ferroc-diagnostics`, `ferroc-values` and `ferroc-syntax`.

#![forbid(unsafe_code)]

pub mod checks;
pub mod ir;
pub mod library;
pub mod load;
pub mod resolve;

use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};
use ferroc_diagnostics::source::{self, SourceMap};
use load::{Loader, Options};
/// Library manifests loaded by name, as `<use library>` finds them.
pub struct LoadedLibraries {
    pub sources: SourceMap,
    pub libraries: library::LibrarySet,
    pub diagnostics: Vec<Diagnostic>,
}

/// Loads the named libraries (and their dependencies) from the lib path or the
/// built-ins, without a model: for commands about libraries (`ferroc types`).
/// Problems are returned as diagnostics; those about a name point into a pseudo-file
/// `<command line>` holding the names.
pub fn load_manifests(names: &[String], options: &Options) -> LoadedLibraries {
    let mut sources = SourceMap::default();
    let mut diags = Diagnostics::default();
    let command_line = names.join(" ");
    let file = sources.add(
        "<command line>".into(),
        std::path::PathBuf::new(),
        command_line,
    );
    let mut loader = Loader::new(&mut sources, &mut diags, options);
    let mut start = 0u32;
    let requests = names
        .iter()
        .map(|name| {
            let end = start + name.len() as u32;
            let span = source::Span { file, start, end };
            start = end + 1;
            library::LibraryRequest {
                name: name.clone(),
                manifest: None,
                span,
                from_file: file,
            }
        })
        .collect();
    let (libraries, _) = library::load_libraries(&mut loader, requests);
    LoadedLibraries {
        sources,
        libraries,
        diagnostics: diags.items,
    }
}
