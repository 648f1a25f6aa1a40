//! The FINROC files around the one being checked: its checkout. A group instance loads
//! its `*.h.xml`, a parameter link names an entry of a config file; to judge these the
//! front end looks at the other FINROC files under the checkout's root (the folder given
//! with `--finroc-root`, else the nearest folder up to four levels above holding a
//! `make.xml`, else the file's own folder). Other files are read quietly: their own
//! findings belong to their own check.

use super::config::{self, ConfigFile};
use super::finstructable::Finstructable;
use super::{kind_of, kind_of_root, read, Kind};
use ferroc_diagnostics::diagnostic::Diagnostics;
use ferroc_diagnostics::source::SourceMap;
use ferroc_model::load::{root_element_of, Options};
use ferroc_syntax::xml;
use std::path::{Path, PathBuf};

/// At most this many files are looked at below a root (a checkout, not a disk).
const MAX_FILES: usize = 5000;
const MAX_DEPTH: usize = 10;

/// A group file of the checkout.
pub struct GroupFile {
    pub path: PathBuf,
    pub doc: Finstructable,
}

#[derive(Default)]
pub struct Checkout {
    pub root: PathBuf,
    pub configs: Vec<ConfigFile>,
    pub groups: Vec<GroupFile>,
    /// The libraries the checkout's make.xml files build (their reference names) and the
    /// target prefixes their folders tell.
    pub built: Vec<String>,
    pub prefixes: Vec<String>,
}

impl Checkout {
    /// The root of the checkout `file` belongs to.
    pub fn root_of(file: &Path, given: Option<&Path>) -> PathBuf {
        if let Some(g) = given {
            return g.to_path_buf();
        }
        // A file named without a folder (`CrashCourse.finroc`) lies in the current one:
        // its parent is the empty path, which names no folder to look in.
        let dir = match file.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let mut up = dir.clone();
        for _ in 0..4 {
            if up.join("make.xml").is_file() {
                return up;
            }
            if !up.pop() {
                break;
            }
        }
        dir
    }

    /// Reads the config, group and make files below `root` (other than `except`) into
    /// `sources`, each as `options` reads it: an editor's unsaved text of a file stands
    /// in for it (`ferroc lsp`), as for a model's fragments and manifests.
    /// `prefix` is the target prefix given for the checkout's make.xml files, if any.
    pub fn discover(
        root: &Path,
        except: &Path,
        options: &Options,
        prefix: Option<String>,
        sources: &mut SourceMap,
    ) -> Checkout {
        let mut found = Vec::new();
        walk(root, 0, &mut found);
        found.sort();
        let except = except
            .canonicalize()
            .unwrap_or_else(|_| except.to_path_buf());
        let mut checkout = Checkout {
            root: root.to_path_buf(),
            ..Checkout::default()
        };
        // A prefix given for the checkout tells its place in the FINROC tree even where
        // no make.xml says it (group-file binding uses it).
        checkout.prefixes.extend(prefix.clone());
        let mut quiet = Diagnostics::default();
        for path in found {
            let canonical = path.canonicalize().unwrap_or_else(|_| path.clone());
            if canonical == except {
                continue;
            }
            // An open file's kind is that of the text on screen.
            let kind = match options.overlay.get(&canonical) {
                Some(text) => kind_of_root(root_element_of(text.as_bytes()).as_deref(), &path),
                None => kind_of(&path),
            };
            if !matches!(kind, Some(Kind::Structure | Kind::Config | Kind::Make)) {
                continue;
            }
            let Ok(text) = options.read(&canonical) else {
                continue;
            };
            let file = sources.add(path.display().to_string(), canonical, text);
            let max_depth = options.limits.max_depth;
            let Ok(tree) = xml::parse(file, &sources.get(file).text, max_depth) else {
                continue;
            };
            match kind {
                Some(Kind::Config) => checkout.configs.push(config::read(file, &tree, &mut quiet)),
                Some(Kind::Make) => {
                    let prefix = prefix
                        .clone()
                        .or_else(|| super::make_xml::target_prefix(&path));
                    let make = super::make_xml::read(file, &tree, prefix.as_deref());
                    for t in make
                        .targets
                        .iter()
                        .filter(|t| t.kind == super::make_xml::TargetKind::Library)
                    {
                        checkout.built.extend(t.reference_names.iter().cloned());
                    }
                    checkout.prefixes.extend(prefix);
                }
                _ => checkout.groups.push(GroupFile {
                    doc: read::read(file, &tree, &mut quiet),
                    path,
                }),
            }
        }
        checkout
    }

    /// The group file a FINROC file name refers to (`XML file` value or a catalogue
    /// group's file): the one sharing the longest tail of path components, at least the
    /// file name.
    pub fn group_file(&self, name: &str) -> Option<&GroupFile> {
        let want: Vec<&str> = name.split('/').filter(|s| !s.is_empty()).collect();
        let score = |g: &GroupFile| {
            let have: Vec<String> = g
                .path
                .components()
                .map(|c| c.as_os_str().to_string_lossy().into_owned())
                .collect();
            want.iter()
                .rev()
                .zip(have.iter().rev())
                .take_while(|(a, b)| **a == b.as_str())
                .count()
        };
        self.groups
            .iter()
            .map(|g| (score(g), g))
            .filter(|(s, _)| *s > 0)
            .max_by_key(|(s, _)| *s)
            .map(|(_, g)| g)
    }

    /// The config files holding an entry at `path`.
    pub fn config_entry(&self, path: &str) -> Option<(&ConfigFile, &config::ConfigEntry)> {
        self.configs
            .iter()
            .find_map(|c| c.entry(path).map(|e| (c, e)))
    }
}

fn walk(dir: &Path, depth: usize, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        if out.len() >= MAX_FILES {
            return;
        }
        if entry.file_name().to_string_lossy().starts_with('.') {
            continue;
        }
        let Ok(kind) = entry.file_type() else {
            continue;
        };
        let path = entry.path();
        if kind.is_dir() && depth < MAX_DEPTH {
            walk(&path, depth + 1, out);
        } else if kind.is_file()
            && path
                .extension()
                .is_some_and(|e| e == "xml" || e == "finroc")
        {
            out.push(path);
        }
    }
}
