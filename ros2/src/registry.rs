//! The packages a program knows: the shipped ones and any a team adds by pointing at
//! their folders. Resolves nested types (every named type exists, no cycles).
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use crate::def::{Arity, BaseType, Field, FieldType, Message, Place, Service, TypeName};
use crate::error::DefinitionError;
use crate::parse::{parse_message, parse_service};

/// The shipped definitions: (`package/kind/Name.kind`, text), embedded by `build.rs`.
const SHIPPED: &[(&str, &str)] = include!(concat!(env!("OUT_DIR"), "/shipped.rs"));

/// A definition file larger than this is refused (the largest shipped one is under 8 KiB).
const MAX_FILE_BYTES: u64 = 1 << 20;

/// One definition file of a team's package, as [`Registry::shipped_with`] takes it.
#[derive(Debug, Clone, Copy)]
pub struct TeamFile<'t> {
    pub package: &'t str,
    /// `msg` or `srv`.
    pub kind: &'t str,
    /// The type's name (the file's stem).
    pub name: &'t str,
    pub text: &'t str,
    /// The file as errors name it.
    pub file: &'t str,
}

/// Message and service types by full name.
#[derive(Debug, Clone, Default)]
pub struct Registry {
    messages: BTreeMap<TypeName, Message>,
    services: BTreeMap<TypeName, Service>,
}

impl Registry {
    /// An empty registry.
    pub fn new() -> Self {
        Registry::default()
    }

    /// The shipped packages: std_msgs, builtin_interfaces, geometry_msgs, sensor_msgs,
    /// nav_msgs, std_srvs and service_msgs. (Their parsing and resolution is tested, so
    /// a failure here is a defect of this crate.)
    pub fn shipped() -> Self {
        let mut registry = Registry::new();
        for (path, text) in SHIPPED {
            let (package, kind, name) = split_shipped(path);
            registry
                .add_text(package, kind, name, text, &format!("<shipped>/{path}"))
                .expect("shipped definitions parse");
        }
        let errors = registry.check();
        assert!(errors.is_empty(), "shipped definitions resolve: {errors:?}");
        registry
    }

    /// [`shipped`](Self::shipped), parsed once per process and shared (the checks and
    /// the plan read it only when a model names ROS 2).
    pub fn shipped_shared() -> &'static Registry {
        static SHIPPED_ONCE: std::sync::OnceLock<Registry> = std::sync::OnceLock::new();
        SHIPPED_ONCE.get_or_init(Registry::shipped)
    }

    /// The file names of the shipped definitions (`std_msgs/msg/Header.msg`, …).
    pub fn shipped_files() -> impl Iterator<Item = &'static str> {
        SHIPPED.iter().map(|(path, _)| *path)
    }

    /// The shipped packages with a team's definitions added (`<ros2-interfaces>` in a
    /// model): every file parsed, then every nested type resolved across all packages.
    /// A file of a shipped package's name is refused (a team package cannot redefine
    /// `std_msgs`); every problem is returned, the registry holds what did parse.
    pub fn shipped_with<'t>(
        files: impl IntoIterator<Item = TeamFile<'t>>,
    ) -> (Registry, Vec<DefinitionError>) {
        let mut registry = Registry::shipped_shared().clone();
        let shipped = Registry::shipped_shared().packages();
        let mut errors = Vec::new();
        for f in files {
            if shipped.contains(f.package) {
                errors.push(DefinitionError::new(
                    f.file,
                    1,
                    1,
                    format!("package `{}` is one ferroc ships", f.package),
                    "a team package cannot redefine a shipped one: give yours its own name",
                ));
                continue;
            }
            if let Err(e) = registry.add_text(f.package, f.kind, f.name, f.text, f.file) {
                errors.push(e);
            }
        }
        errors.extend(registry.check());
        (registry, errors)
    }

    /// The packages the registry's types come from.
    pub fn packages(&self) -> BTreeSet<&str> {
        let messages = self.messages.keys().map(|n| n.package.as_str());
        let services = self.services.keys().map(|n| n.package.as_str());
        messages.chain(services).collect()
    }

    /// Adds one definition from its text: `kind` is `msg` or `srv`.
    pub fn add_text(
        &mut self,
        package: &str,
        kind: &str,
        name: &str,
        text: &str,
        file: &str,
    ) -> Result<(), DefinitionError> {
        let full = TypeName::new(package, kind, name);
        if self.messages.contains_key(&full) || self.services.contains_key(&full) {
            return Err(DefinitionError::new(
                file,
                1,
                1,
                format!("`{full}` is defined twice"),
                "a type is defined by one file; remove one of the two packages or rename it",
            ));
        }
        if kind == "srv" {
            let service = parse_service(text, package, name, file)?;
            let event = event_message(&service);
            self.messages
                .insert(service.request.name.clone(), service.request.clone());
            self.messages
                .insert(service.response.name.clone(), service.response.clone());
            self.messages.insert(event.name.clone(), event);
            self.services.insert(full, service);
        } else {
            self.messages
                .insert(full, parse_message(text, package, name, file)?);
        }
        Ok(())
    }

    /// Adds a package from its folder (named as the package) with `msg/` and `srv/`
    /// subfolders, as a ROS 2 package has them. Returns every error found.
    pub fn add_package(&mut self, folder: &Path) -> Result<(), Vec<DefinitionError>> {
        let shown = folder.display().to_string();
        let package = folder
            .file_name()
            .and_then(|n| n.to_str())
            .ok_or_else(|| vec![io_error(&shown, "the folder has no usable name")])?;
        let mut errors = Vec::new();
        let mut found = false;
        for kind in ["msg", "srv"] {
            let dir = folder.join(kind);
            let Ok(entries) = std::fs::read_dir(&dir) else {
                continue;
            };
            let mut files: Vec<_> = entries.filter_map(Result::ok).map(|e| e.path()).collect();
            files.sort();
            for path in files
                .iter()
                .filter(|p| p.extension().is_some_and(|e| e == kind))
            {
                found = true;
                let shown = path.display().to_string();
                let Some(name) = path.file_stem().and_then(|s| s.to_str()) else {
                    errors.push(io_error(&shown, "the file name is not UTF-8"));
                    continue;
                };
                match read_limited(path) {
                    Ok(text) => {
                        if let Err(e) = self.add_text(package, kind, name, &text, &shown) {
                            errors.push(e);
                        }
                    }
                    Err(why) => errors.push(io_error(&shown, &why)),
                }
            }
        }
        if !found {
            errors.push(io_error(
                &shown,
                "no `msg/*.msg` or `srv/*.srv` files in this folder",
            ));
        }
        if errors.is_empty() {
            Ok(())
        } else {
            Err(errors)
        }
    }

    /// Every nested type named exists, and nested types form no cycle.
    pub fn check(&self) -> Vec<DefinitionError> {
        let mut errors = Vec::new();
        for message in self.messages.values() {
            for field in &message.fields {
                if let BaseType::Nested(name) = &field.ty.base {
                    if !self.messages.contains_key(name) {
                        errors.push(unknown_type(message, field, name));
                    }
                }
            }
        }
        if errors.is_empty() {
            errors.extend(self.find_cycle());
        }
        errors
    }

    /// A message type by full name.
    pub fn message(&self, name: &TypeName) -> Option<&Message> {
        self.messages.get(name)
    }

    /// A service type by full name.
    pub fn service(&self, name: &TypeName) -> Option<&Service> {
        self.services.get(name)
    }

    /// Every message type (including services' request, response and event messages).
    pub fn messages(&self) -> impl Iterator<Item = &Message> {
        self.messages.values()
    }

    /// Every service type.
    pub fn services(&self) -> impl Iterator<Item = &Service> {
        self.services.values()
    }

    /// The first cycle of nested types, reported at the field that closes it.
    fn find_cycle(&self) -> Option<DefinitionError> {
        // 0 = unvisited, 1 = on the current path, 2 = done.
        let mut state: BTreeMap<&TypeName, u8> = BTreeMap::new();
        let mut path: Vec<(&TypeName, Option<&Field>)> = Vec::new();
        for start in self.messages.keys() {
            if let Some(e) = self.visit(start, &mut state, &mut path) {
                return Some(e);
            }
        }
        None
    }

    fn visit<'a>(
        &'a self,
        name: &'a TypeName,
        state: &mut BTreeMap<&'a TypeName, u8>,
        path: &mut Vec<(&'a TypeName, Option<&'a Field>)>,
    ) -> Option<DefinitionError> {
        match state.get(name) {
            Some(2) => return None,
            Some(1) => return Some(self.cycle_error(name, path)),
            _ => {}
        }
        state.insert(name, 1);
        let message = self.messages.get(name)?;
        for field in &message.fields {
            if let BaseType::Nested(inner) = &field.ty.base {
                path.push((name, Some(field)));
                if let Some(e) = self.visit(inner, state, path) {
                    return Some(e);
                }
                path.pop();
            }
        }
        state.insert(name, 2);
        None
    }

    fn cycle_error(
        &self,
        back_to: &TypeName,
        path: &[(&TypeName, Option<&Field>)],
    ) -> DefinitionError {
        let from = path.iter().position(|(n, _)| *n == back_to).unwrap_or(0);
        let mut chain: Vec<String> = path[from..].iter().map(|(n, _)| n.to_string()).collect();
        chain.push(back_to.to_string());
        let (owner, field) = path.last().expect("a cycle has a field");
        let field = field.expect("a step of a cycle is a field");
        let file = self.messages.get(*owner).map_or("", |m| m.file.as_str());
        DefinitionError::new(
            file,
            field.place.line,
            field.place.col,
            format!(
                "nested types form a cycle: {} (a message cannot contain itself)",
                chain.join(" → ")
            ),
            "remove or change one of these fields so that no message contains itself \
             (ROS 2 refuses recursive types, also through arrays)",
        )
    }
}

/// `std_msgs/msg/Header.msg` → (`std_msgs`, `msg`, `Header`).
fn split_shipped(path: &str) -> (&str, &str, &str) {
    let mut parts = path.split('/');
    let package = parts.next().expect("package");
    let kind = parts.next().expect("kind");
    let file = parts.next().expect("file");
    let name = file.rsplit_once('.').expect("extension").0;
    (package, kind, name)
}

/// rosidl's event message of a service: `info`, `request[<=1]`, `response[<=1]`.
fn event_message(service: &Service) -> Message {
    let nested = |name: &TypeName, arity| FieldType {
        base: BaseType::Nested(name.clone()),
        arity,
    };
    let field = |name: &str, ty| Field {
        name: name.to_string(),
        ty,
        default: None,
        comment: String::new(),
        unit: None,
        // Derived, not written: errors about it point at the service file's start.
        place: Place { line: 1, col: 1 },
    };
    let info = TypeName::new("service_msgs", "msg", "ServiceEventInfo");
    Message {
        name: service.event_name(),
        fields: vec![
            field("info", nested(&info, Arity::Single)),
            field("request", nested(&service.request.name, Arity::Bounded(1))),
            field(
                "response",
                nested(&service.response.name, Arity::Bounded(1)),
            ),
        ],
        constants: Vec::new(),
        file: service.file.clone(),
    }
}

fn unknown_type(message: &Message, field: &Field, name: &TypeName) -> DefinitionError {
    DefinitionError::new(
        &message.file,
        field.place.line,
        field.place.col,
        format!("unknown type `{name}` (field `{}`)", field.name),
        &format!(
            "no package read defines `{name}`: fix the name, or add the folder of package \
             `{}` (its `msg/` holds `{}.msg`)",
            name.package, name.name
        ),
    )
}

fn io_error(file: &str, why: &str) -> DefinitionError {
    DefinitionError::new(
        file,
        1,
        1,
        format!("cannot read the definition: {why}"),
        "point at a package folder holding `msg/` or `srv/` with readable files",
    )
}

/// The file's text, refusing huge or non-UTF-8 files.
fn read_limited(path: &Path) -> Result<String, String> {
    let meta = std::fs::metadata(path).map_err(|e| e.to_string())?;
    if meta.len() > MAX_FILE_BYTES {
        return Err(format!(
            "the file has {} bytes; a definition has at most {MAX_FILE_BYTES}",
            meta.len()
        ));
    }
    let bytes = std::fs::read(path).map_err(|e| e.to_string())?;
    String::from_utf8(bytes).map_err(|_| "the file is not UTF-8 text".to_string())
}
