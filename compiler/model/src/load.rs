//! Reading files: models, includes, manifests and config files, with limits, root
//! confinement and cycle detection. All I/O of a check run happens here.

use crate::checks::*;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};
use ferroc_diagnostics::source::{FileId, SourceMap, Span};
use ferroc_syntax::validate::validate;
use ferroc_syntax::xml::{self, Element};
use ferroc_syntax::AllowRegion;
use std::path::{Path, PathBuf};

mod cache;
mod read;
pub use cache::ParseCache;
use read::{io_reason, over_limit};
pub use read::{is_stdin, read_bounded, read_stdin, read_text, root_element, root_element_of};

/// Bounds that keep hostile input from exhausting memory or the stack.
#[derive(Clone, Debug)]
pub struct Limits {
    pub max_file_bytes: u64,
    pub max_depth: usize,
    pub max_include_depth: usize,
    pub max_instance_depth: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_file_bytes: 256 << 20,
            max_depth: 256,
            max_include_depth: 32,
            max_instance_depth: 64,
        }
    }
}

/// A library whose manifest is compiled into the tool (`ferroc_std`).
#[derive(Clone, Debug)]
pub struct BuiltinLibrary {
    pub name: String,
    pub text: String,
}

#[derive(Clone, Debug, Default)]
pub struct Options {
    /// Folders searched for `NAME.lib.xml`.
    pub lib_path: Vec<PathBuf>,
    pub builtins: Vec<BuiltinLibrary>,
    pub allow_outside_includes: bool,
    pub limits: Limits,
    /// Execution semantics to judge every model by, whatever its `<application
    /// profile>` says (`ferroc check --profile`: audit a configuration as another
    /// framework would run it).
    pub profile: Option<crate::ir::Profile>,
    /// Judge the model as run in lockstep (`ferroc check --lockstep`, `ferroc run
    /// --lockstep`): X106 reports what makes such a run differ from the next.
    pub lockstep: bool,
    /// The root of the FINROC checkout FINROC files are resolved in (`--finroc-root`).
    pub finroc_root: Option<PathBuf>,
    /// The FINROC target prefix of make.xml files (`--finroc-prefix`, e.g. `rrlib_math`).
    pub finroc_prefix: Option<String>,
    /// Texts that stand in for files on disk, by canonical path: an editor's unsaved
    /// buffers (`ferroc lsp`), so a model is checked with the fragments and manifests
    /// as they are being typed. Empty for the command line.
    pub overlay: Overlay,
    /// The trees of the files earlier checks parsed, so that a check after a small
    /// edit parses only what changed (`ferroc lsp`; see [`ParseCache`]). `None` for
    /// the command line.
    pub cache: Option<std::sync::Arc<ParseCache>>,
}

/// Unsaved texts by canonical path, shared between check runs without copying.
pub type Overlay = std::sync::Arc<std::collections::HashMap<PathBuf, std::sync::Arc<str>>>;

impl Options {
    /// The text of the file at `path`: the overlay's when it holds the path, else the
    /// file read within the limits ([`read_text`]). Every reading of a model, fragment,
    /// manifest, group type file or config file goes through here.
    pub fn read(&self, path: &Path) -> Result<String, String> {
        if let Some(text) = self.overlay.get(path) {
            if text.len() as u64 > self.limits.max_file_bytes {
                return Err(over_limit(Some(text.len() as u64), &self.limits));
            }
            return Ok(text.to_string());
        }
        read_text(path, &self.limits)
    }
}

/// Why [`Loader::confine`] refused a path.
#[derive(Debug)]
pub enum Confined {
    /// It leads outside the model's folder.
    Outside,
    /// It cannot be read (the reason in words).
    Unreadable(String),
}

/// A model file and the fragments it includes.
pub struct ModelFiles {
    pub file: FileId,
    pub root: Element,
    /// Included `<fragment>` roots, in include order.
    pub fragments: Vec<(FileId, Element)>,
}

pub struct Loader<'a> {
    pub sources: &'a mut SourceMap,
    pub diags: &'a mut Diagnostics,
    pub allows: Vec<AllowRegion>,
    pub options: &'a Options,
    root_dir: PathBuf,
    /// Standard input, when the model comes from there and was read already.
    stdin_text: Option<String>,
    /// The model's text given in memory (an edited model): its display name and text;
    /// the model's path still decides where includes and manifests are looked for.
    given_text: Option<(String, String)>,
}

impl<'a> Loader<'a> {
    pub fn new(
        sources: &'a mut SourceMap,
        diags: &'a mut Diagnostics,
        options: &'a Options,
    ) -> Self {
        Loader {
            sources,
            diags,
            allows: Vec::new(),
            options,
            root_dir: PathBuf::new(),
            stdin_text: None,
            given_text: None,
        }
    }

    /// Adds text as a file and parses it as an element of context `key` with root `tag`.
    /// Reports malformed XML and vocabulary problems; `None` when there is no usable tree.
    pub fn parse(
        &mut self,
        name: String,
        path: PathBuf,
        text: String,
        key: &str,
    ) -> (FileId, Option<Element>) {
        let file = self.sources.add(name, path, text);
        let Some(mut root) = self.parse_tree(file) else {
            return (file, None);
        };
        let expected = ferroc_syntax::vocabulary::spec(key).tag;
        if root.name != expected {
            let finroc = matches!(root.name.as_str(), "Finstructable" | "FinstructableGroup");
            self.diags.push(
                Diagnostic::new(
                    &m119_wrong_root_element::CHECK,
                    root.name_span,
                    format!("expected a <{expected}> file, found <{}>", root.name),
                )
                .label("root element")
                .help(if finroc {
                    "this is a FINROC file; FINROC import is not supported yet".to_string()
                } else {
                    format!("the root element of this file must be <{expected}>")
                }),
            );
            return (file, None);
        }
        validate(&mut root, key, self.diags, &mut self.allows);
        (file, Some(root))
    }

    /// Parses a file already added, reporting malformed XML (M101) and too deep nesting (M116).
    fn parse_tree(&mut self, file: FileId) -> Option<Element> {
        let source = self.sources.get(file);
        let depth = self.options.limits.max_depth;
        let parsed = match &self.options.cache {
            Some(cache) => cache.parse(&source.path, file, &source.text, depth),
            None => xml::parse(file, &source.text, depth),
        };
        match parsed {
            Ok(root) => Some(root),
            Err(e) => {
                let check = if e.too_deep {
                    &m116_limit_exceeded::CHECK
                } else {
                    &m101_malformed_xml::CHECK
                };
                let help = if e.too_deep {
                    "flatten the structure; the limit protects the checker's stack"
                } else {
                    "fix the XML syntax at this place; nothing else in this file was checked"
                };
                self.diags.push(
                    Diagnostic::new(check, e.span, e.message)
                        .label("here")
                        .help(help),
                );
                None
            }
        }
    }

    /// Reads a FINROC build description (`make.xml`): no vocabulary, no includes.
    /// `Err` when the file itself cannot be read (as for a model).
    pub fn load_make_file(&mut self, path: &Path) -> Result<(FileId, Option<Element>), String> {
        let (canonical, text) = self.read_top(path)?;
        let file = self
            .sources
            .add(path.display().to_string(), canonical, text);
        Ok((file, self.parse_tree(file)))
    }

    /// The file a check starts from: its canonical path and its text. Standard input
    /// (`-`, `/dev/stdin`) is read once, as if it were a file in the current folder.
    fn read_top(&mut self, path: &Path) -> Result<(PathBuf, String), String> {
        let cannot = |r: String| format!("cannot read {}: {r}", path.display());
        if is_stdin(path) {
            let text = match self.stdin_text.take() {
                Some(text) => text,
                None => {
                    read_bounded(std::io::stdin().lock(), &self.options.limits).map_err(cannot)?
                }
            };
            let cwd = std::env::current_dir()
                .and_then(|c| c.canonicalize())
                .unwrap_or_default();
            return Ok((cwd.join("<stdin>"), text));
        }
        let canonical = path.canonicalize().unwrap_or_else(|_| path.to_path_buf());
        let text = self.options.read(&canonical).map_err(cannot)?;
        Ok((canonical, text))
    }

    /// Hands the loader standard input already read (to look at its root element).
    pub fn set_stdin_text(&mut self, text: String) {
        self.stdin_text = Some(text);
    }

    /// Checks `text` as if it were the model at its path (an edited model: includes and
    /// manifests are found as for the file), shown as `name` in diagnostics.
    pub fn set_model_text(&mut self, name: String, text: String) {
        self.given_text = Some((name, text));
    }

    /// Loads a model and its includes. `Err` when the model file itself cannot be read.
    pub fn load_model(&mut self, path: &Path) -> Result<Option<ModelFiles>, String> {
        let (display, canonical, text) = match self.given_text.take() {
            Some((name, text)) => {
                let canonical = path.canonicalize().unwrap_or_else(|_| path.to_path_buf());
                (name, canonical, text)
            }
            None => {
                let (canonical, text) = self.read_top(path)?;
                (path.display().to_string(), canonical, text)
            }
        };
        self.root_dir = canonical
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default();
        let (file, root) = self.parse(display, canonical.clone(), text, "application");
        let Some(root) = root else { return Ok(None) };
        let mut fragments = Vec::new();
        let mut chain = vec![(canonical, None)];
        self.load_includes(&root, file, &mut chain, &mut fragments);
        Ok(Some(ModelFiles {
            file,
            root,
            fragments,
        }))
    }

    fn load_includes(
        &mut self,
        parent: &Element,
        parent_file: FileId,
        chain: &mut Vec<(PathBuf, Option<Span>)>,
        fragments: &mut Vec<(FileId, Element)>,
    ) {
        for include in parent.children_named("include") {
            let Some(href) = include.attr("href") else {
                continue;
            };
            let span = href.value_span;
            let Some(target) = self.include_target(parent_file, href.value, span, chain) else {
                continue;
            };
            if let Some(existing) = self.sources.find(&target) {
                // Included twice without a cycle (a diamond): read once.
                let _ = existing;
                continue;
            }
            let text = match self.options.read(&target) {
                Ok(t) => t,
                Err(reason) => {
                    self.diags.push(
                        Diagnostic::new(
                            &m115_file_not_found::CHECK,
                            span,
                            format!("cannot read `{}`: {reason}", href.value),
                        )
                        .label("named here")
                        .help("the path is relative to the file that holds the <include>"),
                    );
                    continue;
                }
            };
            let (file, root) =
                self.parse(self.display_name(&target), target.clone(), text, "fragment");
            if let Some(root) = root {
                chain.push((target, Some(span)));
                self.load_includes(&root, file, chain, fragments);
                chain.pop();
                fragments.push((file, root));
            }
        }
    }

    /// The file an `<include href>` in `parent_file` names (at `span`), made
    /// canonical; `None`, reported, when includes nest too deep, the file lies outside
    /// the model's folder or cannot be found, or including it closes a cycle.
    fn include_target(
        &mut self,
        parent_file: FileId,
        href: &str,
        span: Span,
        chain: &[(PathBuf, Option<Span>)],
    ) -> Option<PathBuf> {
        if chain.len() > self.options.limits.max_include_depth {
            self.diags.push(
                Diagnostic::new(
                    &m116_limit_exceeded::CHECK,
                    span,
                    format!(
                        "includes nest more than {} deep",
                        self.options.limits.max_include_depth
                    ),
                )
                .label("one include too many")
                .help("flatten the include structure"),
            );
            return None;
        }
        let target = match self.confine(parent_file, href) {
            Ok(t) => t,
            Err(Confined::Outside) => {
                self.report_outside(span, href, "included fragments");
                return None;
            }
            Err(Confined::Unreadable(reason)) => {
                self.report_missing(parent_file, span, href, "include", &reason);
                return None;
            }
        };
        if let Some(pos) = chain.iter().position(|(p, _)| *p == target) {
            let mut d = Diagnostic::new(
                &m114_include_cycle::CHECK,
                span,
                format!("including `{}` closes a cycle", href),
            )
            .label("this include leads back to a file that is being included");
            for (_, from) in chain[pos + 1..].iter() {
                if let Some(from) = from {
                    d = d.secondary(*from, "part of the cycle");
                }
            }
            self.diags.push(
                d.help("move the shared group types into a fragment that both files include"),
            );
            return None;
        }
        Some(target)
    }

    /// A path named in `file`, resolved against that file's folder and made canonical.
    /// Reports a missing file (as M115) and returns `None`.
    pub fn resolve_relative(
        &mut self,
        file: FileId,
        rel: &str,
        span: Span,
        what: &str,
    ) -> Option<PathBuf> {
        match self.folder_of(file).join(rel).canonicalize() {
            Ok(p) => Some(p),
            Err(e) => {
                self.report_missing(file, span, rel, what, &io_reason(&e));
                None
            }
        }
    }

    fn report_missing(&mut self, file: FileId, span: Span, rel: &str, what: &str, reason: &str) {
        let base = self.folder_of(file);
        self.diags.push(
            Diagnostic::new(
                &m115_file_not_found::CHECK,
                span,
                format!("cannot read {what} `{rel}`: {reason}"),
            )
            .label("named here")
            .help(format!(
                "the path is relative to {}",
                self.display_name(&base)
            )),
        );
    }

    /// A path written in `file` (an include, a config file), resolved and confined to
    /// the model's folder unless `--allow-outside-includes`. Confinement is judged on
    /// the written path first, so that a hostile `../../etc/passwd` is refused whether
    /// or not that file exists, and then again on the canonical path, so that a
    /// symlink cannot escape either.
    pub fn confine(&self, file: FileId, rel: &str) -> Result<PathBuf, Confined> {
        let allowed = self.options.allow_outside_includes;
        let inside = |p: &Path| allowed || p.starts_with(&self.root_dir);
        if !inside(&lexical_join(&self.folder_of(file), rel)) {
            return Err(Confined::Outside);
        }
        let target = (self.folder_of(file).join(rel).canonicalize())
            .map_err(|e| Confined::Unreadable(io_reason(&e)))?;
        if !inside(&target) {
            return Err(Confined::Outside);
        }
        Ok(target)
    }

    /// M113 for a path that [`confine`](Self::confine) refused; `what` names what must
    /// stay in the model's folder ("included fragments", "config files").
    pub fn report_outside(&mut self, span: Span, rel: &str, what: &str) {
        self.diags.push(
            Diagnostic::new(
                &m113_include_outside_root::CHECK,
                span,
                format!("`{rel}` lies outside the model's directory"),
            )
            .label("resolves outside the model root")
            .help(format!(
                "keep {what} under {}, or pass --allow-outside-includes if you trust this model",
                match self.display_name(&self.root_dir).as_str() {
                    "." => "the current folder".to_string(),
                    folder => folder.to_string(),
                }
            )),
        );
    }

    /// The folder that relative paths written in `file` start from.
    fn folder_of(&self, file: FileId) -> PathBuf {
        self.sources
            .get(file)
            .path
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default()
    }

    /// A path as users should see it: relative to the current directory when possible.
    pub fn display_name(&self, path: &Path) -> String {
        let cwd = std::env::current_dir()
            .ok()
            .and_then(|c| c.canonicalize().ok());
        match cwd.as_deref().and_then(|c| path.strip_prefix(c).ok()) {
            // The current folder itself: `.`, not an empty name.
            Some(rel) if rel.as_os_str().is_empty() => ".".to_string(),
            Some(rel) => rel.display().to_string(),
            None => path.display().to_string(),
        }
    }

    /// Reads a file that is not XML-validated against the vocabulary (config files).
    pub fn read_plain(&mut self, path: &Path) -> Result<(FileId, Option<Element>), String> {
        if let Some(id) = self.sources.find(path) {
            let text = &self.sources.get(id).text;
            return Ok((id, xml::parse(id, text, self.options.limits.max_depth).ok()));
        }
        let text = self.options.read(path)?;
        let file = self
            .sources
            .add(self.display_name(path), path.to_path_buf(), text);
        let text = &self.sources.get(file).text;
        match xml::parse(file, text, self.options.limits.max_depth) {
            Ok(root) => Ok((file, Some(root))),
            Err(e) => {
                self.diags.push(
                    Diagnostic::new(&m101_malformed_xml::CHECK, e.span, e.message)
                        .label("here")
                        .help("fix the XML syntax of this config file"),
                );
                Ok((file, None))
            }
        }
    }
}

/// `base` joined with `rel`, with `.` and `..` resolved on the text alone (no file
/// system access), so that a path can be judged before anything is read.
fn lexical_join(base: &Path, rel: &str) -> PathBuf {
    use std::path::Component;
    let mut out = PathBuf::new();
    for part in base.join(rel).components() {
        match part {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

#[cfg(test)]
mod lexical_tests {
    use super::lexical_join;
    use std::path::Path;

    #[test]
    fn parent_components_are_resolved_without_the_file_system() {
        let base = Path::new("/a/b/c");
        assert_eq!(
            lexical_join(base, "../../../../../etc/passwd"),
            Path::new("/etc/passwd")
        );
        assert_eq!(
            lexical_join(base, "./d/../e.xml"),
            Path::new("/a/b/c/e.xml")
        );
        assert_eq!(lexical_join(base, "/abs/x.xml"), Path::new("/abs/x.xml"));
    }
}
