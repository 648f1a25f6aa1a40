//! The texts the editor has open, by canonical path, kept as the client edits them
//! (full or incremental sync); they stand in for the files on disk in every check.

use crate::position::{Encoding, LineIndex};
use ferroc_compiler::load::Overlay;
use lsp_types::{TextDocumentContentChangeEvent, Url};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// One open document.
pub struct Document {
    pub uri: Url,
    pub version: i32,
    pub text: String,
    pub lines: LineIndex,
}

#[derive(Default)]
pub struct Documents {
    open: HashMap<PathBuf, Document>,
}

/// The path a `file:` URI names, made canonical when the file exists (so that it
/// matches the paths the compiler's sources carry); `None` for other schemes.
pub fn path_of(uri: &Url) -> Option<PathBuf> {
    let path = uri.to_file_path().ok()?;
    Some(path.canonicalize().unwrap_or(path))
}

/// The URI of a path (the open document's own URI when it is open).
pub fn uri_of(docs: &Documents, path: &Path) -> Option<Url> {
    match docs.open.get(path) {
        Some(d) => Some(d.uri.clone()),
        None => Url::from_file_path(path).ok(),
    }
}

impl Documents {
    pub fn open(&mut self, path: PathBuf, uri: Url, version: i32, text: String) {
        let lines = LineIndex::new(&text);
        self.open.insert(
            path,
            Document {
                uri,
                version,
                text,
                lines,
            },
        );
    }

    pub fn close(&mut self, path: &Path) {
        self.open.remove(path);
    }

    pub fn get(&self, path: &Path) -> Option<&Document> {
        self.open.get(path)
    }

    /// Applies the client's changes in order: a change with a range replaces that
    /// range, one without replaces the whole text. `false` when the document is not open.
    pub fn change(
        &mut self,
        path: &Path,
        version: i32,
        changes: Vec<TextDocumentContentChangeEvent>,
        enc: Encoding,
    ) -> bool {
        let Some(doc) = self.open.get_mut(path) else {
            return false;
        };
        for change in changes {
            match change.range {
                None => doc.text = change.text,
                Some(range) => {
                    let start = doc.lines.offset(&doc.text, range.start, enc);
                    let end = doc.lines.offset(&doc.text, range.end, enc).max(start);
                    doc.text.replace_range(start..end, &change.text);
                }
            }
            doc.lines = LineIndex::new(&doc.text);
        }
        doc.version = version;
        true
    }

    /// Every open text, for a check run.
    pub fn overlay(&self) -> Overlay {
        Arc::new(
            self.open
                .iter()
                .map(|(p, d)| (p.clone(), Arc::from(d.text.as_str())))
                .collect(),
        )
    }
}
