//! The checked model's source text as messages and edits need it: a span as
//! `FILE:LINE:COL`, the model file's text.

use ferroc_compiler::report::json::location;
use ferroc_compiler::source::{FileId, SourceMap, Span};
use std::path::Path;

/// `FILE:LINE:COL` of a span.
pub fn at(sources: &SourceMap, span: Span) -> String {
    let l = location(sources, span);
    format!(
        "{}:{}:{}",
        l["file"].as_str().unwrap_or("?"),
        l["line"],
        l["column"]
    )
}

/// The text of the model file as it was checked.
pub fn model_text(model: &Path, sources: &SourceMap) -> String {
    let canonical = model.canonicalize().unwrap_or_else(|_| model.to_path_buf());
    let file = sources.find(&canonical).unwrap_or(FileId(0));
    sources.get(file).text.clone()
}
