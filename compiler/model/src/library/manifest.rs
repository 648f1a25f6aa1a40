//! Finding, reading and registering library manifests, their `<depends>` and group types.

use super::{Dependency, GroupTypeDecl, Library, LibraryId, LibraryRequest, LibrarySet};
use crate::checks::m111_unknown_type;
use crate::checks::*;
use crate::load::Loader;
use ferroc_diagnostics::diagnostic::{did_you_mean, Diagnostic};
use ferroc_diagnostics::source::FileId;
use ferroc_syntax::Element;
use hashbrown::HashMap;
use std::path::{Path, PathBuf};

pub(super) fn load_one(
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
    let (file, root) = parse_manifest(loader, &request, path.clone(), text)?;
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
    let depends = load_depends(loader, set, &root, file, depth);
    set.libraries[id.0 as usize].depends = depends;
    Some(id)
}

/// Parses the manifest found for `request` at `path`; `None` (reported) when it cannot
/// be read or defines another library.
fn parse_manifest(
    loader: &mut Loader<'_>,
    request: &LibraryRequest,
    path: PathBuf,
    text: String,
) -> Option<(FileId, Element)> {
    let display = if path.as_os_str().is_empty() {
        format!("<built-in {}.lib.xml>", request.name)
    } else {
        loader.display_name(&path)
    };
    let (file, root) = loader.parse(display, path, text, "library");
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
    Some((file, root))
}

/// The `<depends>` of a manifest (in `file`), each loaded unless the chain of
/// dependencies is too deep.
fn load_depends(
    loader: &mut Loader<'_>,
    set: &mut LibrarySet,
    root: &Element,
    file: FileId,
    depth: usize,
) -> Vec<Dependency> {
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
    depends
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
    let path = loader.resolve_relative(file, rel.value, rel.value_span, "group type file")?;
    let text = match loader.options.read(&path) {
        Ok(t) => t,
        Err(reason) => {
            loader.diags.push(
                Diagnostic::new(
                    &crate::checks::m115_file_not_found::CHECK,
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

/// The include rule applied to `manifest=`: a manifest in the model's folder is read
/// whatever its name; one outside it only if it is named `*.lib.xml`, as written and
/// after symlinks (libraries usually sit next to the models, `../components/x.lib.xml`),
/// unless `--allow-outside-includes`. So a model cannot make the checker read and
/// show an arbitrary file (`/etc/shadow`). `Err` names what must stay inside.
fn manifest_allowed(
    loader: &Loader<'_>,
    from: FileId,
    rel: &str,
    canonical: &Path,
) -> Result<(), &'static str> {
    let named = |p: &Path| p.to_string_lossy().ends_with(".lib.xml");
    match loader.confine(from, rel) {
        Err(crate::load::Confined::Outside) if !(named(Path::new(rel)) && named(canonical)) => {
            Err("manifests not named *.lib.xml")
        }
        _ => Ok(()),
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
        if let Err(why) = manifest_allowed(loader, request.from_file, rel, &path) {
            loader.report_outside(request.span, rel, why);
            return None;
        }
        return match loader.options.read(&path) {
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
            if let Ok(text) = loader.options.read(&path) {
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
