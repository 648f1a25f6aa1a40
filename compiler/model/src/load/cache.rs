//! What a check may keep for the next one (`ferroc lsp`): the syntax tree of each file
//! it parsed, with the text it was parsed from. The next check of an unchanged file
//! takes the tree as it is; a file changed by a keystroke is parsed again only in the
//! element the edit lies in (`ferroc_syntax::xml::reparse`). Validation and everything
//! after it run as without a cache, so the findings are the same. `ferroc check` passes
//! no cache.

use ferroc_diagnostics::source::FileId;
use ferroc_syntax::xml::{self, Element, XmlError};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// At most this many files are kept (a workspace's models, fragments and manifests);
/// beyond it the file used longest ago goes.
const MAX_FILES: usize = 64;

/// The trees of the files the last checks parsed, by path. Shared by the checks that
/// use it (`Options::cache`); one check at a time takes a file's entry.
#[derive(Default)]
pub struct ParseCache {
    files: Mutex<Files>,
}

#[derive(Default)]
struct Files {
    by_path: HashMap<PathBuf, Entry>,
    clock: u64,
}

struct Entry {
    text: Box<str>,
    tree: Element,
    used: u64,
}

impl std::fmt::Debug for ParseCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let n = self.files.lock().map_or(0, |f| f.by_path.len());
        write!(f, "ParseCache({n} files)")
    }
}

impl ParseCache {
    /// The tree of `text`, the file at `path` with id `file`: [`xml::parse`]'s result,
    /// made from the kept tree of the file's previous text when there is one.
    pub fn parse(
        &self,
        path: &Path,
        file: FileId,
        text: &str,
        max_depth: usize,
    ) -> Result<Element, XmlError> {
        let kept = self
            .files
            .lock()
            .ok()
            .and_then(|mut f| f.by_path.remove(path));
        let Some(mut entry) = kept else {
            let tree = xml::parse(file, text, max_depth)?;
            self.keep(path, text, tree.clone());
            return Ok(tree);
        };
        match xml::reparse(&mut entry.tree, &entry.text, text, file, max_depth) {
            Ok(()) => {
                let tree = entry.tree.clone();
                if *entry.text != *text {
                    entry.text = text.into();
                }
                self.put(path, entry);
                Ok(tree)
            }
            Err(e) => {
                // The previous text's tree stays: the next edit may make it XML again.
                self.put(path, entry);
                Err(e)
            }
        }
    }

    /// How many files are kept.
    pub fn len(&self) -> usize {
        self.files.lock().map_or(0, |f| f.by_path.len())
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    fn keep(&self, path: &Path, text: &str, tree: Element) {
        let entry = Entry {
            text: text.into(),
            tree,
            used: 0,
        };
        self.put(path, entry);
    }

    fn put(&self, path: &Path, mut entry: Entry) {
        let Ok(mut files) = self.files.lock() else {
            return;
        };
        files.clock += 1;
        entry.used = files.clock;
        files.by_path.insert(path.to_path_buf(), entry);
        while files.by_path.len() > MAX_FILES {
            let oldest = files
                .by_path
                .iter()
                .min_by_key(|(_, e)| e.used)
                .map(|(p, _)| p.clone());
            match oldest {
                Some(p) => files.by_path.remove(&p),
                None => break,
            };
        }
    }
}
