//! `ferroc_std.Logger`: appends its inputs to a file, one JSON line per period:
//! `{"time":"2026-12-01T16:10:20.123456Z","in/0":1.5,"in/1":"Pose2D { x: 1.0, .. }"}`.
//!
//! Numbers are JSON numbers (`null` if not finite), `bool`s JSON booleans, strings and
//! timestamps JSON strings, and library types their `Debug` text as a JSON string (the
//! runtime has no serde; every line is still valid JSON, so `jq` reads the log).
//!
//! The path is checked when the module is created, without touching the file system
//! beyond reading metadata (creation must stay free of side effects): an empty path,
//! control characters, `..` components, a folder that is not one, or something that
//! exists but is not a regular file (a folder, a device, a symbolic link) are refused
//! with an error naming the module. The file is opened (created if missing, appended
//! to) at the first write, its folders created first as a deployment expects of a log
//! (`/var/log/agv/`); if that or a later write fails, the logger reports it once and
//! stops logging rather than stopping the application. The path is fixed at creation: setting `file`
//! while running changes nothing (`period` takes effect at once).

use ferroc_runtime::module::{DynIn, Module, ModuleType, Parameter, Setup, Timestamp};
use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::{Component, Path, PathBuf};
use std::time::Duration;

/// `ferroc_std.Logger`: writes its inputs to a log file at a fixed period.
pub struct Logger {
    inputs: Vec<DynIn>,
    path: PathBuf,
    period: Parameter<Duration>,
    file: Option<File>,
    /// Writing failed once: reported, nothing more is written.
    failed: bool,
    /// When the next line is due (`None`: at once), on `Timestamp::now`'s clock (model
    /// time in lockstep, so a lockstep run logs the same lines every time).
    next: Option<Duration>,
    line: String,
}

impl ModuleType for Logger {
    const NAME: &'static str = "ferroc_std.Logger";
    const DOC: &'static str = "Writes its inputs to a log file at a fixed period";
    fn create(m: &mut Setup<'_>) -> Self {
        let inputs = m.flexible_inputs("in").min_count(1).build_dyn();
        let mut file: Parameter<String> = m
            .param("file")
            .doc("path of the log file, created if missing")
            .build();
        let period = m
            .param("period")
            .default(Duration::from_secs(1))
            .range(0.001, 3600.0)
            .doc("how often a line is written")
            .build();
        let path = PathBuf::from(file.value());
        // The registry learning the interface gives no path: nothing to check then.
        if !m.path().is_empty() {
            if let Err(why) = check_log_path(&path) {
                m.problem(format!("parameter `file`: {why}"));
            }
        }
        Logger {
            inputs,
            path,
            period,
            file: None,
            failed: false,
            next: None,
            line: String::new(),
        }
    }
}

/// Whether `path` may name a log file: see the [module docs](self).
pub fn check_log_path(path: &Path) -> Result<(), String> {
    let text = path.to_string_lossy();
    if text.trim().is_empty() {
        return Err("the path of the log file is empty".into());
    }
    if text.chars().any(char::is_control) {
        return Err(format!("the path {text:?} contains control characters"));
    }
    if path.components().any(|c| c == Component::ParentDir) {
        return Err(format!(
            "the path `{text}` climbs out of a folder with `..`: name the file directly"
        ));
    }
    if text.ends_with('/') || path.file_name().is_none() {
        return Err(format!("the path `{text}` names a folder, not a file"));
    }
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    // A missing folder is created at the first write; an existing non-folder is wrong.
    if let Some(not_folder) = folder
        .ancestors()
        .find(|a| a.exists())
        .filter(|a| !a.is_dir())
    {
        return Err(format!(
            "`{}` in the path of the log file is not a folder",
            not_folder.display()
        ));
    }
    match std::fs::symlink_metadata(path) {
        Ok(meta) if meta.file_type().is_file() => Ok(()),
        Ok(meta) => Err(format!(
            "`{text}` exists and is not a regular file but {}",
            if meta.file_type().is_symlink() {
                "a symbolic link"
            } else if meta.is_dir() {
                "a folder"
            } else {
                "a special file"
            }
        )),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(format!("`{text}` cannot be inspected: {e}")),
    }
}

/// Opens `path` for appending, creating it and its missing folders.
fn open_log(path: &Path) -> std::io::Result<File> {
    if let Some(folder) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(folder)?;
    }
    OpenOptions::new().create(true).append(true).open(path)
}

impl Logger {
    /// This period's line: the time, then every input by name.
    fn format_line(&mut self, now: Timestamp) {
        use std::fmt::Write as _;
        self.line.clear();
        let _ = write!(self.line, "{{\"time\":\"{now}\"");
        for input in &self.inputs {
            // Port names are `group/k`: nothing in them needs escaping.
            let _ = write!(self.line, ",\"{}\":", input.name());
            input.write_json(&mut self.line);
        }
        self.line.push_str("}\n");
    }

    fn write_line(&mut self) -> std::io::Result<()> {
        if self.file.is_none() {
            self.file = Some(open_log(&self.path)?);
        }
        match &mut self.file {
            Some(f) => f.write_all(self.line.as_bytes()),
            None => Ok(()),
        }
    }
}

impl Module for Logger {
    fn update(&mut self) {
        if self.failed {
            return;
        }
        let stamp = Timestamp::now();
        let now = Duration::from_nanos(u64::try_from(stamp.nanos).unwrap_or(0));
        let period = self.period.get();
        // Due from half a period before the deadline: a thread container of the same
        // period starts each cycle a little late or early, and a strict comparison
        // would skip every other line. Deadlines advance by whole periods, so the rate
        // is exact; after a long stall the schedule restarts instead of catching up.
        if self.next.is_some_and(|next| now + period / 2 < next) {
            return;
        }
        self.next = Some(match self.next {
            Some(next) if now < next + period => next + period,
            _ => now + period,
        });
        self.format_line(stamp);
        if let Err(e) = self.write_line() {
            self.failed = true;
            eprintln!(
                "warning: ferroc_std.Logger cannot write `{}`: {e}; it logs nothing more",
                self.path.display()
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn missing_folders_are_accepted_and_created_at_the_first_write() {
        let dir = std::env::temp_dir().join(format!("ferroc-logger-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let path = dir.join("agv/trajectory.log");
        assert_eq!(check_log_path(&path), Ok(()));
        assert!(!dir.exists(), "checking creates nothing");
        let mut file = open_log(&path).unwrap();
        file.write_all(b"{}\n").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "{}\n");
        // A file where a folder should be is refused when checked.
        let e = check_log_path(&path.join("x.log")).unwrap_err();
        assert!(e.contains("is not a folder"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
