//! Writing the bundle: every file is prepared in memory first, named by a path relative
//! to DIR whose every component is checked, and written only below DIR (never through a
//! symbolic link, never outside): into a folder beside DIR first, moved into place only
//! once all of it is written, so a full disk never leaves a half-written bundle.

use std::collections::BTreeMap;
use std::path::{Component, Path, PathBuf};

/// The files of a bundle, by relative path (`/`-separated), sorted.
#[derive(Default)]
pub struct Files {
    files: BTreeMap<String, (Vec<u8>, bool)>,
}

impl Files {
    /// Adds a file; `rel` must be a safe relative path (see [`safe_relative`]).
    pub fn add(&mut self, rel: &str, contents: impl Into<Vec<u8>>) -> Result<(), String> {
        self.insert(rel, contents.into(), false)
    }

    /// Adds an executable file (a launch script).
    pub fn add_executable(
        &mut self,
        rel: &str,
        contents: impl Into<Vec<u8>>,
    ) -> Result<(), String> {
        self.insert(rel, contents.into(), true)
    }

    fn insert(&mut self, rel: &str, contents: Vec<u8>, exec: bool) -> Result<(), String> {
        safe_relative(rel)?;
        if self
            .files
            .insert(rel.to_string(), (contents, exec))
            .is_some()
        {
            return Err(format!("two generated files are named `{rel}`"));
        }
        Ok(())
    }

    pub fn paths(&self) -> impl Iterator<Item = &str> {
        self.files.keys().map(String::as_str)
    }
}

/// A relative path made of plain components: letters, digits, `-`, `_`, `.`; no empty,
/// `.` or `..` component, not absolute.
pub fn safe_relative(rel: &str) -> Result<(), String> {
    let ok = !rel.is_empty()
        && !rel.starts_with('/')
        && rel.split('/').all(|c| {
            !c.is_empty()
                && c != "."
                && c != ".."
                && c.chars()
                    .all(|ch| ch.is_ascii_alphanumeric() || matches!(ch, '-' | '_' | '.'))
        })
        && Path::new(rel)
            .components()
            .all(|c| matches!(c, Component::Normal(_)));
    if ok {
        Ok(())
    } else {
        Err(format!(
            "refusing to write `{}`: not a plain path inside the bundle folder",
            rel.escape_debug()
        ))
    }
}

/// Why the output folder cannot be used (exit code 2). Gives the folder's absolute
/// path with its parent's links resolved; it is not created here: [`write`] makes
/// the bundle beside it and renames it into place.
pub fn prepare_dir(dir: &Path, force: bool) -> Result<PathBuf, String> {
    let shown = dir.display();
    if dir == Path::new("-") {
        return Err(
            "`-o -` cannot name the bundle: a bundle is a folder of files, not a \
             stream for standard output\n  help: name a folder, e.g. `-o bundle`"
                .into(),
        );
    }
    match std::fs::symlink_metadata(dir) {
        Ok(meta) if meta.file_type().is_symlink() => {
            Err(format!(
                "{shown} is a symbolic link; give the real folder it points to (a bundle is never written through a link)"
            ))
        }
        Ok(meta) if !meta.is_dir() => {
            Err(format!("{shown} exists and is not a folder"))
        }
        Ok(_) => {
            let mut entries = std::fs::read_dir(dir)
                .map_err(|e| format!("cannot read {shown}: {e}"))?;
            if entries.next().is_some() && !force {
                return Err(format!(
                    "{shown} is not empty; choose an empty or new folder, or pass --force to overwrite the bundle's files in it"
                ));
            }
            dir.canonicalize()
                .map_err(|e| format!("cannot resolve {shown}: {e}"))
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            let absolute =
                std::path::absolute(dir).map_err(|e| format!("cannot use {shown}: {e}"))?;
            let (Some(parent), Some(name)) = (absolute.parent(), absolute.file_name()) else {
                return Err(format!("{shown} cannot name a new folder"));
            };
            std::fs::create_dir_all(parent)
                .map_err(|e| format!("cannot create {}: {e}", parent.display()))?;
            let parent = parent
                .canonicalize()
                .map_err(|e| format!("cannot resolve {}: {e}", parent.display()))?;
            Ok(parent.join(name))
        }
        Err(e) => Err(format!("cannot use {shown}: {e}")),
    }
}

/// Writes every file of the bundle whose folder is `root` (from [`prepare_dir`]):
/// first into a new folder beside it, where `finish` may still change them (rustfmt),
/// then into place: the folder renamed to `root` (new or empty), or with `--force`
/// each file renamed into the existing `root`. A failure on the way (a full disk)
/// leaves `root` as it was and removes the folder beside it. A symbolic link met in
/// `root` (planted in a folder given with `--force`) stops it.
pub fn write(root: &Path, files: &Files, finish: impl FnOnce(&Path)) -> Result<(), String> {
    let (Some(parent), Some(name)) = (root.parent(), root.file_name()) else {
        return Err(format!("{} cannot hold a bundle", root.display()));
    };
    let staging = parent.join(format!(
        ".{}.ferroc-bundle-{}",
        name.to_string_lossy(),
        std::process::id()
    ));
    std::fs::create_dir(&staging)
        .map_err(|e| format!("cannot create {}: {e}", staging.display()))?;
    let written = write_files(&staging, files).and_then(|()| {
        finish(&staging);
        publish(&staging, root, files)
    });
    if staging.exists() {
        let _ = std::fs::remove_dir_all(&staging);
    }
    written
}

/// Moves the bundle written in `staging` to `root`.
fn publish(staging: &Path, root: &Path, files: &Files) -> Result<(), String> {
    let empty = match std::fs::read_dir(root) {
        Ok(mut entries) => entries.next().is_none(),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => true,
        Err(e) => return Err(format!("cannot read {}: {e}", root.display())),
    };
    if empty {
        // A new folder, or one replacing an empty folder: one step.
        return std::fs::rename(staging, root)
            .map_err(|e| format!("cannot move the bundle to {}: {e}", root.display()));
    }
    // Every place checked (no link in the way) before any file moves.
    let places = (files.files.keys())
        .map(|rel| place(root, rel).map(|to| (staging.join(rel), to)))
        .collect::<Result<Vec<_>, String>>()?;
    for (from, to) in places {
        std::fs::rename(from, &to)
            .map_err(|e| format!("cannot move {} into place: {e}", to.display()))?;
    }
    Ok(())
}

/// Writes every file below `root`.
fn write_files(root: &Path, files: &Files) -> Result<(), String> {
    for (rel, (contents, exec)) in &files.files {
        let at = place(root, rel)?;
        std::fs::write(&at, contents).map_err(|e| format!("cannot write {}: {e}", at.display()))?;
        set_mode(&at, *exec)
            .map_err(|e| format!("cannot set the mode of {}: {e}", at.display()))?;
    }
    Ok(())
}

/// Where the file `rel` goes below `root`: its folders made, no symbolic link or
/// folder in the way.
fn place(root: &Path, rel: &str) -> Result<PathBuf, String> {
    safe_relative(rel)?;
    let mut at = root.to_path_buf();
    let components: Vec<&str> = rel.split('/').collect();
    for (i, c) in components.iter().enumerate() {
        at.push(c);
        let last = i + 1 == components.len();
        match std::fs::symlink_metadata(&at) {
            Ok(m) if m.file_type().is_symlink() => {
                return Err(format!(
                    "{} is a symbolic link; refusing to write through it",
                    at.display()
                ))
            }
            Ok(m) if !last && !m.is_dir() => {
                return Err(format!("{} is in the way (not a folder)", at.display()))
            }
            Ok(m) if last && m.is_dir() => {
                return Err(format!("{} is in the way (a folder)", at.display()))
            }
            Ok(_) => {}
            Err(_) if !last => std::fs::create_dir(&at)
                .map_err(|e| format!("cannot create {}: {e}", at.display()))?,
            Err(_) => {}
        }
    }
    Ok(at)
}

#[cfg(unix)]
fn set_mode(path: &Path, exec: bool) -> std::io::Result<()> {
    use std::os::unix::fs::PermissionsExt;
    let mode = if exec { 0o755 } else { 0o644 };
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(mode))
}

#[cfg(not(unix))]
fn set_mode(_: &Path, _: bool) -> std::io::Result<()> {
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::safe_relative;

    #[test]
    fn only_plain_relative_paths() {
        assert!(safe_relative("parts/robot/src/main.rs").is_ok());
        for bad in [
            "",
            "/etc/passwd",
            "../x",
            "a/../b",
            "a//b",
            "./a",
            "a/.",
            "a\\b",
            "a b",
            "a\n",
        ] {
            assert!(safe_relative(bad).is_err(), "{bad:?}");
        }
    }
}
