//! Library manifests: loading (use → depends), the dependency graph, and the tables of
//! data types, module types and group types that models refer to.

use crate::load::Loader;
use ferroc_diagnostics::diagnostic::Diagnostic;
use ferroc_diagnostics::source::{FileId, Span};
use ferroc_syntax::Element;
use ferroc_values::types::{NamedTypeId, Type};
use ferroc_values::units::{parse_unit, Unit};
use hashbrown::HashMap;
use std::path::PathBuf;

mod data_types;
mod manifest;
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
    /// The ROS 2 message the type's crate maps it to (`ros2="sensor_msgs/msg/Image"`:
    /// `Registry::register_ros2`), which check R102 accepts instead of matching field
    /// by field.
    pub ros2: Option<String>,
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
    pub fn field_of(
        &self,
        t: &Type,
        field: &str,
    ) -> Option<(&Type, Option<&ferroc_values::units::Unit>)> {
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
        roots.push(manifest::load_one(loader, &mut set, request, 0));
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
    crate::checks::l103_dependency_cycle::report_cycles(&set, loader.diags);
    data_types::register_types(&mut set, loader.diags);
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

/// Parses an optional `unit` attribute, reporting a bad unit as an invalid value.
pub fn unit_attr(
    element: &Element,
    diags: &mut ferroc_diagnostics::diagnostic::Diagnostics,
) -> Option<Unit> {
    let attr = element.attr("unit")?;
    match parse_unit(attr.value) {
        Ok(u) => Some(u),
        Err(e) => {
            diags.push(
                Diagnostic::new(
                    &ferroc_syntax::checks::m108_invalid_attribute_value::CHECK,
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
