//! The table of named data types: registering manifests' `<type>`s, resolving type expressions.

use super::{unit_attr, LibraryId, LibrarySet, NamedType};
use crate::checks::l104_library_not_used;
use crate::checks::m111_unknown_type;
use ferroc_diagnostics::diagnostic::{did_you_mean, Diagnostic};
use ferroc_diagnostics::source::Span;
use ferroc_values::types::{parse_type, NamedTypeId, Type, TypeError};

impl LibrarySet {
    /// Parses a type expression written in a file that may use `visible` libraries.
    /// Reports unknown types (M111) and types from libraries not in scope (L104).
    pub fn resolve_type(
        &self,
        text: &str,
        span: Span,
        visible: &[LibraryId],
        diags: &mut ferroc_diagnostics::diagnostic::Diagnostics,
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
            None => match did_you_mean(q, ferroc_values::types::BUILTIN_NAMES.iter().copied()) {
                Some(s) => d.help(format!("did you mean `{s}`?")),
                None => d.help("types are built-in (`f64`, `u8[4]`, `[f64]`) or `library.Type`"),
            },
        }
    }
}

/// First pass over types: names, then fields (which may refer to other types).
pub(super) fn register_types(
    set: &mut LibrarySet,
    diags: &mut ferroc_diagnostics::diagnostic::Diagnostics,
) {
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
                        &crate::checks::m109_duplicate_name::CHECK,
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
                ros2: t.value("ros2").map(str::to_string),
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
