//! The model's own ROS 2 packages (`<ros2-interfaces>`): their definition files, read
//! into the model's sources while resolving, parsed and resolved beside the shipped
//! packages. Every check of area R looks types up in the result; R109 reports what is
//! wrong in it.

use ferroc_diagnostics::source::{FileId, SourceMap, Span};
use ferroc_model::ir::{Application, Ros2Interfaces};
use ferroc_ros2::{DefinitionError, Registry, TeamFile};
use std::collections::{BTreeSet, HashMap};

/// The shipped packages with the model's, and the problems of the model's packages.
pub(crate) struct Team {
    pub registry: Registry,
    /// Problems of the definition files, each at its place in its file.
    pub errors: Vec<(Span, DefinitionError)>,
}

/// Why a `<ros2-interfaces>` adds no definitions, if it adds none.
pub(crate) enum Refused {
    /// Its package is one ferroc ships.
    Shipped,
    /// An earlier `<ros2-interfaces>` names the same package (its span).
    Twice(Span),
}

impl Team {
    /// Parses and resolves the model's packages (those [`refused`] does not refuse).
    pub(crate) fn read(app: &Application, sources: &SourceMap) -> Team {
        let mut by_name: HashMap<&str, FileId> = HashMap::new();
        let mut files = Vec::new();
        for (i, interfaces) in app.ros2.interfaces.iter().enumerate() {
            if refused(app, i).is_some() {
                continue;
            }
            let Ok(read) = &interfaces.files else {
                continue;
            };
            for f in read {
                let source = sources.get(f.file);
                by_name.insert(source.name.as_str(), f.file);
                files.push(TeamFile {
                    package: &interfaces.package.0,
                    kind: f.kind,
                    name: &f.name,
                    text: &source.text,
                    file: &source.name,
                });
            }
        }
        let (registry, errors) = Registry::shipped_with(files);
        let errors = errors
            .into_iter()
            .filter_map(|e| {
                let file = *by_name.get(e.file.as_str())?;
                Some((place(sources, file, e.line, e.col), e))
            })
            .collect();
        Team { registry, errors }
    }
}

/// Why the `index`th `<ros2-interfaces>` of `app` is not read, if it is not.
pub(crate) fn refused(app: &Application, index: usize) -> Option<Refused> {
    let all = &app.ros2.interfaces;
    let package = all[index].package.0.as_str();
    if shipped_packages().contains(package) {
        return Some(Refused::Shipped);
    }
    let earlier = all[..index]
        .iter()
        .find(|i: &&Ros2Interfaces| i.package.0 == package)?;
    Some(Refused::Twice(earlier.package.1))
}

/// The packages ferroc ships.
pub(crate) fn shipped_packages() -> BTreeSet<&'static str> {
    Registry::shipped_shared().packages()
}

/// The span of the word at `line`:`col` (1-based, columns in characters) of `file`.
fn place(sources: &SourceMap, file: FileId, line: usize, col: usize) -> Span {
    let source = sources.get(file);
    let line = line.clamp(1, source.line_count()) - 1;
    let range = source.line_range(line);
    let start = source.offset_of_column(range.start, range.end, col.saturating_sub(1), 1);
    let word = source.text[start..range.end]
        .find(char::is_whitespace)
        .map_or(range.end, |n| start + n);
    Span::new(file, start, word.max(start))
}
