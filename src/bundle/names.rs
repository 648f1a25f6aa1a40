//! Source locations as the bundle's messages and files name them: files relative to the
//! model's folder.

use ferroc_compiler::source::{SourceMap, Span};
use std::path::{Path, PathBuf};

/// Source locations as `file:line:col`, files named relative to the model's folder so
/// the bundle does not depend on where ferroc was started.
pub(super) struct Names<'s> {
    base: Option<PathBuf>,
    sources: &'s SourceMap,
    pub(super) model_file: String,
}

impl<'s> Names<'s> {
    pub(super) fn new(model: &Path, sources: &'s SourceMap) -> Self {
        let base = model
            .canonicalize()
            .ok()
            .and_then(|p| p.parent().map(Path::to_path_buf));
        let model_file = model
            .file_name()
            .map_or_else(|| "model.xml".into(), |f| f.to_string_lossy().into_owned());
        Names {
            base,
            sources,
            model_file,
        }
    }

    pub(super) fn file(&self, file: &ferroc_compiler::source::SourceFile) -> String {
        if let Some(rel) = self
            .base
            .as_ref()
            .and_then(|b| file.path.strip_prefix(b).ok())
        {
            if !rel.as_os_str().is_empty() {
                return rel.to_string_lossy().into_owned();
            }
        }
        if file.path.as_os_str().is_empty() {
            return file.name.clone(); // built in
        }
        let rel = self.base.as_ref().and_then(|b| relative(b, &file.path));
        rel.unwrap_or_else(|| file.name.clone())
    }

    pub(super) fn at(&self, span: Span) -> String {
        let file = self.sources.get(span.file);
        let (line, col) = file.line_col(span.start);
        format!("{}:{line}:{col}", self.file(file))
    }
}

/// `to` relative to the folder `from` (both absolute), with `/` separators.
pub(super) fn relative(from: &Path, to: &Path) -> Option<String> {
    let from: Vec<_> = from.components().collect();
    let to: Vec<_> = to.components().collect();
    let common = from.iter().zip(&to).take_while(|(a, b)| a == b).count();
    // Sharing only the root (`/`): an absolute path reads better than `../../..`.
    if common <= 1 {
        return None;
    }
    let mut parts: Vec<String> = vec!["..".into(); from.len() - common];
    parts.extend(
        to[common..]
            .iter()
            .map(|c| c.as_os_str().to_string_lossy().into_owned()),
    );
    Some(if parts.is_empty() {
        ".".into()
    } else {
        parts.join("/")
    })
}
