//! The field accessors a part's connections need (`<convert field="tasks_done"/>`).
//!
//! `ferroc run` gets them from each library's `register` function; a bundle registers
//! only what it uses, so it writes one `register_field::<S, F>` call per field a
//! connection takes: `S` and `F` from the manifests' `rust=` paths and field types, the
//! accessor reading the Rust field of the manifest field's name.

use super::text;
use ferroc_compiler::library::module_type::PortType;
use ferroc_compiler::library::LibrarySet;
use ferroc_compiler::plan::{Part as ValuePart, PlannedConnection, PlannedModule};
use ferroc_compiler::types::Type;

/// One `registry.register_field::<S, F>(field, |v| …)` call.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct FieldAccessor {
    /// Rust type of the value taken apart.
    pub value: String,
    /// Rust type of the field.
    pub field_type: String,
    pub field: String,
    /// Copy types are read, others cloned.
    pub copy: bool,
}

impl FieldAccessor {
    /// The registration call (one line of generated code).
    pub fn call(&self) -> String {
        let read = if self.copy { "" } else { ".clone()" };
        format!(
            "registry.register_field::<{}, {}>({:?}, |v| v.{}{read});",
            self.value, self.field_type, self.field, self.field
        )
    }
}

/// The Rust type of a model type, and whether it is `Copy` (`None`: no port value type
/// the generated code can name).
pub(super) fn rust_type(libs: &LibrarySet, t: &Type) -> Option<(String, bool)> {
    Some(match t {
        Type::Bool => ("bool".into(), true),
        Type::Int { signed, bits } => (format!("{}{bits}", if *signed { 'i' } else { 'u' }), true),
        Type::Float { bits } => (format!("f{bits}"), true),
        Type::Meta(_) => ("f64".into(), true),
        Type::String => ("String".into(), false),
        Type::Duration => ("std::time::Duration".into(), true),
        Type::Timestamp => ("ferroc_runtime::module::Timestamp".into(), true),
        Type::Seq(e) => (format!("Vec<{}>", rust_type(libs, e)?.0), false),
        Type::Array(e, n) => {
            let (e, copy) = rust_type(libs, e)?;
            (format!("[{e}; {n}]"), copy)
        }
        Type::Named(id, _) => {
            let named = libs.named_type(*id);
            (named.rust.clone(), named.copy)
        }
    })
}

/// The accessors of the fields `c` takes out of its source port's values. Fields it
/// cannot name (a port whose type the instance declares, a field that is not a Rust
/// identifier) get none: building the part then reports the missing accessor.
pub fn accessors(
    c: &PlannedConnection,
    modules: &[&PlannedModule],
    libs: &LibrarySet,
) -> Vec<FieldAccessor> {
    let mut out = Vec::new();
    let Some(module) = modules.iter().find(|m| m.path == c.from.0) else {
        return out;
    };
    let Some(PortType::Fixed(mut current)) = libs
        .module_type(&module.type_name)
        .and_then(|(_, ty)| ty.port(&c.from.1))
        .map(|p| p.ty.clone())
    else {
        return out;
    };
    for part in &c.select {
        let next = match part {
            ValuePart::Index(_) => current.element().cloned(),
            ValuePart::Field(f) => {
                let Some((field_ty, _)) = libs.field_of(&current, f) else {
                    return out;
                };
                let field_ty = field_ty.clone();
                if let (Some((value, _)), Some((field_type, copy))) =
                    (rust_type(libs, &current), rust_type(libs, &field_ty))
                {
                    if text::is_rust_ident(f) && text::is_rust_path(&value) {
                        out.push(FieldAccessor {
                            value,
                            field_type,
                            field: f.clone(),
                            copy,
                        });
                    }
                }
                Some(field_ty)
            }
        };
        match next {
            Some(t) => current = t,
            None => return out,
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn copy_fields_are_read_and_others_cloned() {
        let mut a = FieldAccessor {
            value: "rescue_components::Velocity2D".into(),
            field_type: "f64".into(),
            field: "linear".into(),
            copy: true,
        };
        assert_eq!(
            a.call(),
            r#"registry.register_field::<rescue_components::Velocity2D, f64>("linear", |v| v.linear);"#
        );
        a.field_type = "Vec<f32>".into();
        a.field = "ranges".into();
        a.copy = false;
        assert!(a.call().ends_with(r#"("ranges", |v| v.ranges.clone());"#));
    }
}
