//! Writing the bundle: every file is prepared in memory first, named by a path relative
//! to DIR whose every component is checked, and written only below DIR (never through a
//! symbolic link, never outside).

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

/// Why the output folder cannot be used (exit code 2).
pub fn prepare_dir(dir: &Path, force: bool) -> Result<PathBuf, String> {
    let shown = dir.display();
    match std::fs::symlink_metadata(dir) {
        Ok(meta) if meta.file_type().is_symlink() => {
            return Err(format!(
                "{shown} is a symbolic link; give the real folder it points to (a bundle is never written through a link)"
            ))
        }
        Ok(meta) if !meta.is_dir() => {
            return Err(format!("{shown} exists and is not a folder"))
        }
        Ok(_) => {
            let mut entries = std::fs::read_dir(dir)
                .map_err(|e| format!("cannot read {shown}: {e}"))?;
            if entries.next().is_some() && !force {
                return Err(format!(
                    "{shown} is not empty; choose an empty or new folder, or pass --force to overwrite the bundle's files in it"
                ));
            }
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {shown}: {e}"))?;
        }
        Err(e) => return Err(format!("cannot use {shown}: {e}")),
    }
    dir.canonicalize()
        .map_err(|e| format!("cannot resolve {shown}: {e}"))
}

/// Writes every file below `root` (from [`prepare_dir`]). A symbolic link met on the way
/// (planted in a folder given with `--force`) stops it.
pub fn write(root: &Path, files: &Files) -> Result<(), String> {
    for (rel, (contents, exec)) in &files.files {
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
        std::fs::write(&at, contents).map_err(|e| format!("cannot write {}: {e}", at.display()))?;
        set_mode(&at, *exec)
            .map_err(|e| format!("cannot set the mode of {}: {e}", at.display()))?;
    }
    Ok(())
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
