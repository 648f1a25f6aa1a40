//! What the program running the application tells the recording modules: where
//! relative log paths go, which part each module belongs to (for channel metadata),
//! and the run seed (for the file's metadata). Process-wide, set once before the application is built.

use std::path::{Path, PathBuf};
use std::sync::{Mutex, PoisonError};

static LOG_DIR: Mutex<Option<PathBuf>> = Mutex::new(None);
static RUN_SEED: Mutex<Option<u64>> = Mutex::new(None);
/// (module path prefix, part name), longest prefix first.
static PARTS: Mutex<Vec<(String, String)>> = Mutex::new(Vec::new());

/// Relative log paths resolve against `dir` from now on (`ferroc run --log-dir`).
pub fn set_log_dir(dir: Option<PathBuf>) {
    *LOG_DIR.lock().unwrap_or_else(PoisonError::into_inner) = dir;
}

/// The folder relative log paths resolve against: [`set_log_dir`], else
/// `FERROC_LOG_DIR`, else the working directory (`.`).
pub fn log_dir() -> PathBuf {
    if let Some(dir) = LOG_DIR
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .clone()
    {
        return dir;
    }
    match std::env::var_os("FERROC_LOG_DIR") {
        Some(d) if !d.is_empty() => PathBuf::from(d),
        _ => PathBuf::from("."),
    }
}

/// `path` as the file to write: absolute paths as they are (the model asked for that
/// place), relative ones under [`log_dir`].
pub fn resolve_log_path(path: &Path) -> PathBuf {
    if path.is_absolute() {
        path.to_path_buf()
    } else {
        log_dir().join(path)
    }
}

/// The run seed (`--seed`, or the one chosen and printed at start), which every
/// recording notes in its metadata so that the run can be repeated.
pub fn set_run_seed(seed: u64) {
    *RUN_SEED.lock().unwrap_or_else(PoisonError::into_inner) = Some(seed);
}

/// The run seed, if the program told it.
pub fn run_seed() -> Option<u64> {
    *RUN_SEED.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Tells the recording modules which part holds which module: `(module path, part)`
/// for every module (or every part's top element; the longest prefix wins).
pub fn set_parts(parts: Vec<(String, String)>) {
    let mut parts = parts;
    parts.sort_by(|a, b| b.0.len().cmp(&a.0.len()).then(a.0.cmp(&b.0)));
    *PARTS.lock().unwrap_or_else(PoisonError::into_inner) = parts;
}

/// The part of the module at `path`; empty if none was told.
pub fn part_of(path: &str) -> String {
    let parts = PARTS.lock().unwrap_or_else(PoisonError::into_inner);
    parts
        .iter()
        .find(|(prefix, _)| {
            path == prefix
                || path
                    .strip_prefix(prefix.as_str())
                    .is_some_and(|rest| rest.starts_with('/'))
        })
        .map(|(_, part)| part.clone())
        .unwrap_or_default()
}
