//! What the program running the application tells the recording modules: where
//! relative log paths go, which part each module belongs to and the unit of each port
//! (for channel metadata), and the run seed (for the file's metadata). Process-wide, set once before the application is built.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, PoisonError};

static LOG_DIR: Mutex<Option<PathBuf>> = Mutex::new(None);
static RUN_SEED: Mutex<Option<u64>> = Mutex::new(None);
/// (module path prefix, part name), longest prefix first.
static PARTS: Mutex<Vec<(String, String)>> = Mutex::new(Vec::new());
/// (port path, unit), sorted by path.
static UNITS: Mutex<Vec<(String, String)>> = Mutex::new(Vec::new());

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

/// Whether files that are not ferroc recordings may be replaced (`--force`).
static OVERWRITE: AtomicBool = AtomicBool::new(false);

/// From now on, a log file may replace a file that is not a ferroc recording
/// (`ferroc run --force`, a generated program's `--force`).
pub fn set_overwrite(allowed: bool) {
    OVERWRITE.store(allowed, Ordering::SeqCst);
}

/// Whether `path`, a log path a model (or an edit of it) names, lies inside the log
/// folder: relative paths always do (`..` is refused elsewhere); an absolute one only
/// if it leads there, also through symbolic links of folders that exist already.
pub fn check_in_log_dir(path: &Path) -> Result<(), String> {
    let dir = log_dir();
    let file = resolve_log_path(path);
    let inside = match (real(&dir), real(&file)) {
        (Some(dir), Some(file)) => file.starts_with(&dir),
        _ => false,
    };
    if inside {
        return Ok(());
    }
    Err(format!(
        "`{}` lies outside the log folder `{}`: a model writes its logs only there\n  \
         help: name the file relative to the log folder (e.g. `logs/run.mcap`), or choose \
         the folder with `ferroc run --log-dir DIR` (FERROC_LOG_DIR for generated programs)",
        path.display(),
        dir.display()
    ))
}

/// `path` absolute with its existing part's symbolic links resolved (the rest, not
/// created yet, appended as it is); `None` if the existing part cannot be resolved.
fn real(path: &Path) -> Option<PathBuf> {
    let path = std::path::absolute(path).ok()?;
    let mut rest = Vec::new();
    let mut existing = path.as_path();
    loop {
        if let Ok(found) = existing.canonicalize() {
            let mut out = found;
            out.extend(rest.iter().rev());
            return Some(out);
        }
        rest.push(existing.file_name()?.to_owned());
        existing = existing.parent()?;
    }
}

/// Whether the log file at `path` may be written: it does not exist, is empty, or is
/// a recording of ours (MCAP whose header names the library `ferroc`); anything else
/// only after [`set_overwrite`]. Nothing is changed.
pub fn check_overwrite(path: &Path) -> Result<(), String> {
    match std::fs::File::open(path) {
        Ok(mut file) => check_replaceable(path, &mut file),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(format!("`{}` cannot be read: {e}", path.display())),
    }
}

/// [`check_overwrite`] of the open `file` (read from its start).
pub(crate) fn check_replaceable(path: &Path, file: &mut std::fs::File) -> Result<(), String> {
    if OVERWRITE.load(Ordering::SeqCst) {
        return Ok(());
    }
    let mut head = Vec::with_capacity(HEAD);
    file.take(HEAD as u64)
        .read_to_end(&mut head)
        .map_err(|e| format!("`{}` cannot be read: {e}", path.display()))?;
    if head.is_empty() || is_ferroc_recording(&head) {
        return Ok(());
    }
    Err(format!(
        "`{}` exists and is not a ferroc recording: it is not replaced\n  help: name \
         another file, or pass --force to replace it",
        path.display()
    ))
}

/// How much of a file's start tells whether it is a recording of ours.
const HEAD: usize = 4096;

/// Whether `head`, the start of a file, is the start of an MCAP file written by ferroc:
/// the magic, then the header record whose library is `ferroc`.
pub fn is_ferroc_recording(head: &[u8]) -> bool {
    fn string(bytes: &[u8]) -> Option<(&[u8], &[u8])> {
        let (len, rest) = bytes.split_first_chunk::<4>()?;
        let len = usize::try_from(u32::from_le_bytes(*len)).ok()?;
        (rest.len() >= len).then(|| rest.split_at(len))
    }
    let Some(rest) = head.strip_prefix(mcap::MAGIC) else {
        return false;
    };
    let Some((&[op], rest)) = rest.split_first_chunk::<1>() else {
        return false;
    };
    let Some((_, rest)) = rest.split_first_chunk::<8>() else {
        return false;
    };
    let library = string(rest)
        .and_then(|(_, rest)| string(rest))
        .map(|(l, _)| l);
    op == 0x01 && library == Some(LIBRARY.as_bytes())
}

/// The library named in the header of every recording ferroc writes.
pub const LIBRARY: &str = "ferroc";

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

/// Tells the recording modules the unit of the values at each port: `(port path,
/// unit)` as the run plan has them (an input's own unit, else the unit of what feeds
/// it). Ports not named have no unit.
pub fn set_units<S: AsRef<str>>(units: &[(S, S)]) {
    let mut units: Vec<(String, String)> = units
        .iter()
        .map(|(p, u)| (p.as_ref().to_owned(), u.as_ref().to_owned()))
        .collect();
    units.sort();
    units.dedup_by(|a, b| a.0 == b.0);
    *UNITS.lock().unwrap_or_else(PoisonError::into_inner) = units;
}

/// The unit of the values at the port `path` (`robot/log/in/0`); empty if none was
/// told.
pub fn unit_of(path: &str) -> String {
    let units = UNITS.lock().unwrap_or_else(PoisonError::into_inner);
    units
        .binary_search_by(|(p, _)| p.as_str().cmp(path))
        .map(|k| units[k].1.clone())
        .unwrap_or_default()
}
