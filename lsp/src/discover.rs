//! Finding the models that may use a fragment or manifest nobody opened a model for:
//! the application models in the workspace folders (or, without any, in the file's
//! folder and the one above), searched as `ferroc check FOLDER` does, bounded.

use std::path::{Path, PathBuf};

/// At most this many models are found (each is checked once to learn what it reads).
const MAX_MODELS: usize = 200;
const MAX_DEPTH: usize = 8;
/// At most this many directory entries are looked at.
const MAX_ENTRIES: usize = 20_000;

pub fn models(workspace: &[PathBuf], file: &Path) -> Vec<PathBuf> {
    let mut dirs: Vec<PathBuf> = workspace.to_vec();
    if dirs.is_empty() {
        let parent = file.parent().map(Path::to_path_buf);
        dirs.extend(
            parent
                .as_deref()
                .and_then(Path::parent)
                .map(Path::to_path_buf)
                .or(parent),
        );
    }
    let mut out = Vec::new();
    let mut seen = 0;
    for dir in dirs {
        walk(&dir, 0, &mut out, &mut seen);
    }
    out.sort();
    out.dedup();
    out
}

fn walk(dir: &Path, depth: usize, out: &mut Vec<PathBuf>, seen: &mut usize) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        *seen += 1;
        if out.len() >= MAX_MODELS || *seen > MAX_ENTRIES {
            return;
        }
        let path = entry.path();
        let name = entry.file_name();
        let name = name.to_string_lossy();
        if name.starts_with('.') || name == "target" || name == "node_modules" {
            continue;
        }
        let Ok(kind) = entry.file_type() else {
            continue;
        };
        if kind.is_dir() && depth < MAX_DEPTH {
            walk(&path, depth + 1, out, seen);
        } else if kind.is_file()
            && name.ends_with(".xml")
            && !name.ends_with(".lib.xml")
            && ferroc_compiler::load::root_element(&path).as_deref() == Some("application")
        {
            out.push(path.canonicalize().unwrap_or(path));
        }
    }
}
