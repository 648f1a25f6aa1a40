//! Library manifests: loading (use → depends), the dependency graph, and the tables of
//! data types, module types and group types that models refer to.

use crate::checks::libraries::*;
use crate::checks::model::m111_unknown_type;
use crate::diagnostic::{did_you_mean, Diagnostic};
use crate::load::Loader;
use crate::source::{FileId, Span};
use crate::syntax::Element;
use crate::types::{parse_type, NamedTypeId, Type, TypeError};
use crate::units::{parse_unit, Unit};
use hashbrown::HashMap;
use std::path::{Path, PathBuf};

pub mod module_type;
pub mod steps;
pub use module_type::{ModuleKind, ModuleType, ParamDecl, PortDecl, PortDir, PortRole, PortType};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct LibraryId(pub u32);

#[derive(Debug)]
pub struct Dependency {
    pub library: String,
    pub span: Span,
    /// Resolved target, when it loaded.
    pub target: Option<LibraryId>,
}

#[derive(Debug)]
pub struct NamedType {
    pub library: LibraryId,
    pub qualified: String,
    pub rust: String,
    pub copy: bool,
    pub serde: bool,
    pub fields: Vec<(String, Type, Option<Unit>)>,
    pub span: Span,
}

#[derive(Debug)]
pub struct GroupTypeDecl {
    pub name: String,
    pub file: FileId,
    pub element: Element,
}

#[derive(Debug)]
pub struct Library {
    pub name: String,
    pub file: FileId,
    pub path: PathBuf,
    pub rust_crate: Option<String>,
    pub version: Option<String>,
    pub depends: Vec<Dependency>,
    pub module_types: Vec<ModuleType>,
    pub module_index: HashMap<String, usize>,
    pub group_types: Vec<GroupTypeDecl>,
    /// This library and everything it depends on, directly or not.
    pub visible: Vec<LibraryId>,
    /// The manifest's `name` attribute value.
    pub name_span: Span,
    root: Element,
}

/// Every library of a check run.
#[derive(Debug, Default)]
pub struct LibrarySet {
    pub libraries: Vec<Library>,
    pub by_name: HashMap<String, LibraryId>,
    pub types: Vec<NamedType>,
    pub type_index: HashMap<String, NamedTypeId>,
    /// Libraries that were asked for but could not be loaded. Their failure is reported
    /// once (L101/L102); references to their types stay silent instead of repeating it.
    pub failed: hashbrown::HashSet<String>,
}

impl Library {
    /// The manifest's syntax tree (`ferroc types export` keeps what the code cannot say).
    pub fn root(&self) -> &Element {
        &self.root
    }
}

impl LibrarySet {
    pub fn get(&self, id: LibraryId) -> &Library {
        &self.libraries[id.0 as usize]
    }

    pub fn named_type(&self, id: NamedTypeId) -> &NamedType {
        &self.types[id.0 as usize]
    }

    /// The type and unit of `field` in values of `t` (a named type with that field).
    pub fn field_of(&self, t: &Type, field: &str) -> Option<(&Type, Option<&crate::units::Unit>)> {
        let Type::Named(id, _) = t else {
            return None;
        };
        let (_, ty, unit) = self
            .named_type(*id)
            .fields
            .iter()
            .find(|(f, _, _)| f == field)?;
        Some((ty, unit.as_ref()))
    }

    /// Whether values of `t` can cross a process boundary.
    pub fn serialisable(&self, t: &Type) -> bool {
        match t {
            Type::Named(id, _) => self.named_type(*id).serde,
            Type::Array(e, _) | Type::Seq(e) => self.serialisable(e),
            _ => true,
        }
    }

    /// Resolves `lib.Module` for a file that may use the libraries in `visible`.
    pub fn module_type(&self, qualified: &str) -> Option<(LibraryId, &ModuleType)> {
        let (lib, name) = qualified.split_once('.')?;
        let id = *self.by_name.get(lib)?;
        let library = self.get(id);
        library
            .module_index
            .get(name)
            .map(|i| (id, &library.module_types[*i]))
    }

    /// Parses a type expression written in a file that may use `visible` libraries.
    /// Reports unknown types (M111) and types from libraries not in scope (L104).
    pub fn resolve_type(
        &self,
        text: &str,
        span: Span,
        visible: &[LibraryId],
        diags: &mut crate::diagnostic::Diagnostics,
    ) -> Option<Type> {
        let mut not_visible = None;
        let result = parse_type(text, &mut |q| {
            let id = *self.type_index.get(q)?;
            if !visible.contains(&self.named_type(id).library) {
                not_visible = Some(q.to_string());
            }
            Some(id)
        });
        if let Some(q) = not_visible {
            let lib = q.split_once('.').map_or("", |(l, _)| l);
            diags.push(
                Diagnostic::new(
                    &l104_library_not_used::CHECK,
                    span,
                    format!("type `{q}` comes from library `{lib}`, which this file does not use"),
                )
                .label("library not in scope")
                .help(format!(
                    "add <use library=\"{lib}\"/> (or <depends library=\"{lib}\"/> in a manifest)"
                )),
            );
        }
        match result {
            Ok(t) => Some(t),
            Err(TypeError::Syntax(msg)) => {
                diags.push(
                    Diagnostic::new(
                        &m111_unknown_type::CHECK,
                        span,
                        format!("`{text}` is not a type: {msg}"),
                    )
                    .label("invalid type")
                    .help("types are built-in (`f64`, `u8[4]`, `[f64]`) or `library.Type`"),
                );
                None
            }
            Err(TypeError::Unknown(q)) => {
                let from_failed = q
                    .split_once('.')
                    .is_some_and(|(lib, _)| self.failed.contains(lib));
                if !from_failed {
                    diags.push(self.unknown_type_diagnostic(&q, span));
                }
                None
            }
        }
    }

    fn unknown_type_diagnostic(&self, q: &str, span: Span) -> Diagnostic {
        let d = Diagnostic::new(
            &m111_unknown_type::CHECK,
            span,
            format!("unknown data type `{q}`"),
        )
        .label("no such type");
        match q.split_once('.') {
            Some((lib, name)) if self.by_name.contains_key(lib) => {
                let names = self
                    .types
                    .iter()
                    .filter_map(|t| t.qualified.strip_prefix(lib)?.strip_prefix('.'));
                match did_you_mean(name, names) {
                    Some(s) => d.help(format!("did you mean `{lib}.{s}`?")),
                    None => d.help(format!("library `{lib}` defines no type `{name}`")),
                }
            }
            Some((lib, _)) => d.help(format!(
                "library `{lib}` is not loaded; add <use library=\"{lib}\"/>"
            )),
            None => match did_you_mean(q, crate::types::BUILTIN_NAMES.iter().copied()) {
                Some(s) => d.help(format!("did you mean `{s}`?")),
                None => d.help("types are built-in (`f64`, `u8[4]`, `[f64]`) or `library.Type`"),
            },
        }
    }
}

/// A request to load a library: from `<use>` or `<depends>`.
pub struct LibraryRequest {
    pub name: String,
    pub manifest: Option<String>,
    pub span: Span,
    pub from_file: FileId,
}

/// Loads the requested libraries and everything they depend on, then builds the tables.
/// Returns the ids of the requested libraries (those that loaded).
pub fn load_libraries(
    loader: &mut Loader<'_>,
    requests: Vec<LibraryRequest>,
) -> (LibrarySet, Vec<Option<LibraryId>>) {
    let mut set = LibrarySet::default();
    let mut roots = Vec::new();
    for request in requests {
        roots.push(load_one(loader, &mut set, request, 0));
    }
    for i in 0..set.libraries.len() {
        let id = LibraryId(i as u32);
        let mut visible = vec![id];
        let mut k = 0;
        while k < visible.len() {
            let lib = &set.libraries[visible[k].0 as usize];
            for dep in lib.depends.iter().filter_map(|d| d.target) {
                if !visible.contains(&dep) {
                    visible.push(dep);
                }
            }
            k += 1;
        }
        set.libraries[i].visible = visible;
    }
    crate::checks::libraries::l103_dependency_cycle::report_cycles(&set, loader.diags);
    register_types(&mut set, loader.diags);
    for i in 0..set.libraries.len() {
        let module_types = module_type::build_all(&set, LibraryId(i as u32), loader.diags);
        let lib = &mut set.libraries[i];
        lib.module_index = module_types
            .iter()
            .enumerate()
            .map(|(k, m)| (m.name.clone(), k))
            .collect();
        lib.module_types = module_types;
    }
    (set, roots)
}

fn load_one(
    loader: &mut Loader<'_>,
    set: &mut LibrarySet,
    request: LibraryRequest,
    depth: usize,
) -> Option<LibraryId> {
    let name = request.name.clone();
    let loaded = load_manifest(loader, set, request, depth);
    if loaded.is_none() {
        set.failed.insert(name);
    }
    loaded
}

/// Finds, parses and registers one library; `None` (after reporting why) when it fails.
fn load_manifest(
    loader: &mut Loader<'_>,
    set: &mut LibrarySet,
    request: LibraryRequest,
    depth: usize,
) -> Option<LibraryId> {
    let (path, text) = locate(loader, &request)?;
    if let Some(&existing) = set.by_name.get(&request.name) {
        let lib = set.get(existing);
        if lib.path != path {
            loader.diags.push(
                Diagnostic::new(
                    &l105_conflicting_library::CHECK,
                    request.span,
                    format!(
                        "library `{}` is already loaded from another manifest",
                        request.name
                    ),
                )
                .label(format!("this names {}", loader.display_name(&path)))
                .secondary(lib.name_span, "the manifest loaded first")
                .help("point every <use>/<depends> of this library at the same manifest"),
            );
        }
        return Some(existing);
    }
    let display = if path.as_os_str().is_empty() {
        format!("<built-in {}.lib.xml>", request.name)
    } else {
        loader.display_name(&path)
    };
    let (file, root) = loader.parse(display, path.clone(), text, "library");
    let Some(root) = root else {
        loader.diags.push(
            Diagnostic::new(
                &l102_invalid_manifest::CHECK,
                request.span,
                format!("the manifest of `{}` could not be read", request.name),
            )
            .label("named here")
            .help("fix the manifest (see the findings in it)"),
        );
        return None;
    };
    let declared = root.value("name").unwrap_or("");
    if declared != request.name {
        loader.diags.push(
            Diagnostic::new(
                &l102_invalid_manifest::CHECK,
                request.span,
                format!(
                    "the manifest defines library `{declared}`, not `{}`",
                    request.name
                ),
            )
            .label("asks for this library")
            .secondary(root.value_span("name"), "the manifest's name")
            .help("correct the library name or the manifest path"),
        );
        return None;
    }
    let id = LibraryId(set.libraries.len() as u32);
    set.by_name.insert(request.name.clone(), id);
    let mut group_types = Vec::new();
    for gt in root.children_named("group-type") {
        group_types.push(load_group_type(loader, file, gt));
    }
    set.libraries.push(Library {
        name: request.name.clone(),
        file,
        path,
        rust_crate: root.value("rust-crate").map(str::to_string),
        version: root.value("version").map(str::to_string),
        depends: Vec::new(),
        module_types: Vec::new(),
        module_index: HashMap::new(),
        group_types: group_types.into_iter().flatten().collect(),
        visible: Vec::new(),
        name_span: root.value_span("name"),
        root: root.clone(),
    });
    let mut depends = Vec::new();
    for dep in root.children_named("depends") {
        let Some(name) = dep.value("library") else {
            continue;
        };
        let target = if depth >= loader.options.limits.max_include_depth {
            None
        } else {
            load_one(
                loader,
                set,
                LibraryRequest {
                    name: name.to_string(),
                    manifest: dep.value("manifest").map(str::to_string),
                    span: dep.value_span("library"),
                    from_file: file,
                },
                depth + 1,
            )
        };
        depends.push(Dependency {
            library: name.to_string(),
            span: dep.value_span("library"),
            target,
        });
    }
    set.libraries[id.0 as usize].depends = depends;
    Some(id)
}

fn load_group_type(loader: &mut Loader<'_>, file: FileId, gt: &Element) -> Option<GroupTypeDecl> {
    let name = gt.value("name")?.to_string();
    let Some(rel) = gt.attr("file") else {
        return Some(GroupTypeDecl {
            name,
            file,
            element: gt.clone(),
        });
    };
    let path = loader.resolve_relative(file, &rel.value, rel.value_span, "group type file")?;
    let text = match crate::load::read_text(&path, &loader.options.limits) {
        Ok(t) => t,
        Err(reason) => {
            loader.diags.push(
                Diagnostic::new(
                    &crate::checks::model::m115_file_not_found::CHECK,
                    rel.value_span,
                    format!("cannot read `{}`: {reason}", rel.value),
                )
                .label("named here"),
            );
            return None;
        }
    };
    let (gfile, root) = loader.parse(loader.display_name(&path), path, text, "fragment");
    let root = root?;
    let found = root
        .children_named("group-type")
        .find(|g| g.value("name") == Some(name.as_str()));
    match found {
        Some(element) => Some(GroupTypeDecl {
            name,
            file: gfile,
            element: element.clone(),
        }),
        None => {
            loader.diags.push(
                Diagnostic::new(
                    &m111_unknown_type::CHECK,
                    rel.value_span,
                    format!("`{}` defines no group type `{name}`", rel.value),
                )
                .label("named here")
                .help(format!("add <group-type name=\"{name}\"> to that fragment")),
            );
            None
        }
    }
}

/// Finds a manifest: the `manifest` path, else the library path, else the built-ins.
fn locate(loader: &mut Loader<'_>, request: &LibraryRequest) -> Option<(PathBuf, String)> {
    if let Some(rel) = &request.manifest {
        let base = loader
            .sources
            .get(request.from_file)
            .path
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default();
        let joined = base.join(rel);
        let path = joined.canonicalize().unwrap_or(joined);
        return match crate::load::read_text(&path, &loader.options.limits) {
            Ok(text) => Some((path, text)),
            Err(reason) => {
                loader.diags.push(
                    Diagnostic::new(
                        &l102_invalid_manifest::CHECK,
                        request.span,
                        format!(
                            "cannot read the manifest of `{}` at `{rel}`: {reason}",
                            request.name
                        ),
                    )
                    .label("library named here")
                    .help(format!(
                        "manifest paths are relative to {}",
                        loader.display_name(&base)
                    )),
                );
                None
            }
        };
    }
    for dir in &loader.options.lib_path {
        let candidate = dir.join(format!("{}.lib.xml", request.name));
        if candidate.is_file() {
            let path = candidate.canonicalize().unwrap_or(candidate);
            if let Ok(text) = crate::load::read_text(&path, &loader.options.limits) {
                return Some((path, text));
            }
        }
    }
    if let Some(b) = loader
        .options
        .builtins
        .iter()
        .find(|b| b.name == request.name)
    {
        return Some((PathBuf::new(), b.text.clone()));
    }
    let known: Vec<&str> = loader
        .options
        .builtins
        .iter()
        .map(|b| b.name.as_str())
        .collect();
    let d = Diagnostic::new(
        &l101_unknown_library::CHECK,
        request.span,
        format!("library `{}` not found", request.name),
    )
    .label("no manifest for this library");
    loader.diags.push(match did_you_mean(&request.name, known) {
        Some(s) => d.help(format!("did you mean `{s}`? Otherwise give manifest=\"path/to/{}.lib.xml\" or add its folder with --lib-path", request.name)),
        None => d.help(format!("give manifest=\"path/to/{}.lib.xml\" or add its folder with --lib-path / FERROC_LIB_PATH", request.name)),
    });
    None
}

/// First pass over types: names, then fields (which may refer to other types).
fn register_types(set: &mut LibrarySet, diags: &mut crate::diagnostic::Diagnostics) {
    let mut pending = Vec::new();
    for (i, lib) in set.libraries.iter().enumerate() {
        for t in lib.root.children_named("type") {
            let Some(name) = t.value("name") else {
                continue;
            };
            let qualified = format!("{}.{name}", lib.name);
            if set.type_index.contains_key(&qualified) {
                diags.push(
                    Diagnostic::new(
                        &crate::checks::model::m109_duplicate_name::CHECK,
                        t.value_span("name"),
                        format!("type `{name}` is defined twice"),
                    )
                    .label("second definition")
                    .help("rename or remove one of them"),
                );
                continue;
            }
            let id = NamedTypeId(set.types.len() as u32);
            set.type_index.insert(qualified.clone(), id);
            set.types.push(NamedType {
                library: LibraryId(i as u32),
                qualified,
                rust: t.value("rust").unwrap_or("").to_string(),
                copy: t.value("copy") == Some("true"),
                serde: t.value("serde") == Some("true"),
                fields: Vec::new(),
                span: t.value_span("name"),
            });
            pending.push((id, i, t.clone()));
        }
    }
    for (id, lib, element) in pending {
        let visible = set.libraries[lib].visible.clone();
        let mut fields = Vec::new();
        for f in element.children_named("field") {
            let (Some(name), Some(ty)) = (f.value("name"), f.value("type")) else {
                continue;
            };
            let Some(t) = set.resolve_type(ty, f.value_span("type"), &visible, diags) else {
                continue;
            };
            let unit = unit_attr(f, diags);
            fields.push((name.to_string(), t, unit));
        }
        set.types[id.0 as usize].fields = fields;
    }
}

/// Parses an optional `unit` attribute, reporting a bad unit as an invalid value.
pub fn unit_attr(element: &Element, diags: &mut crate::diagnostic::Diagnostics) -> Option<Unit> {
    let attr = element.attr("unit")?;
    match parse_unit(&attr.value) {
        Ok(u) => Some(u),
        Err(e) => {
            diags.push(
                Diagnostic::new(
                    &crate::checks::model::m108_invalid_attribute_value::CHECK,
                    attr.value_span,
                    format!("`{}` is not a unit: {e}", attr.value),
                )
                .label("invalid unit")
                .help("use SI symbols with prefixes (`m`, `mm/s`, `m/s^2`), `deg`, `rpm` or `Hz`"),
            );
            None
        }
    }
}
