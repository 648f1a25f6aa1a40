//! Checks of area connections.

pub mod t101_wrong_direction;
pub mod t102_incompatible_types;
pub mod t103_unit_dimension_mismatch;
pub mod t104_implicit_unit_scale;
pub mod t105_unit_on_one_end;
pub mod t106_narrowing_without_convert;
pub mod t107_duplicate_connection;
pub mod t108_multiple_writers;
pub mod t109_required_input_unconnected;
pub mod t110_unused_output;
pub mod t111_not_serialisable_across_parts;
pub mod t112_double_scaling;
pub mod t113_invalid_convert;
pub mod t114_queue_memory_unbounded;

use crate::PassContext;
use ferroc_diagnostics::source::Span;
use ferroc_model::ir::{Connection, Endpoint, PortView};
use ferroc_model::library::PortDir;
use ferroc_values::types::Type;
use std::borrow::Cow;

/// Both ends of a connection, when they resolve.
pub fn ends<'a>(
    app: &'a ferroc_model::ir::Application,
    libraries: &'a ferroc_model::library::LibrarySet,
    c: &Connection,
) -> Option<(PortView<'a>, PortView<'a>)> {
    Some((app.view(libraries, c.from)?, app.view(libraries, c.to)?))
}

/// Whether an endpoint sends data into a connection declared in `scope`.
pub fn emits(c: &Connection, ep: Endpoint, view: &PortView<'_>) -> bool {
    match ep {
        Endpoint::Port { .. } => view.dir == PortDir::Out,
        Endpoint::GroupPort { element, .. } => (element == c.scope) == (view.dir == PortDir::In),
        Endpoint::Param { .. } => false,
    }
}

/// Whether an endpoint receives data from a connection declared in `scope`.
pub fn accepts(c: &Connection, ep: Endpoint, view: &PortView<'_>) -> bool {
    match ep {
        Endpoint::Port { .. } => view.dir == PortDir::In,
        Endpoint::GroupPort { element, .. } => (element == c.scope) == (view.dir == PortDir::Out),
        Endpoint::Param { .. } => true,
    }
}

/// A `<convert>` step that does not apply, with the place to blame.
pub struct ConvertError {
    pub span: Span,
    pub message: String,
}

/// The value's type after source indexing and every `<convert>` step, and the type the
/// destination takes (after destination indexing). Borrowed unless a step changes it.
pub fn flow_types<'a>(
    ctx: &'a PassContext<'a>,
    c: &Connection,
    from: &PortView<'a>,
    to: &PortView<'a>,
) -> Result<(Cow<'a, Type>, Cow<'a, Type>), ConvertError> {
    let mut t = match c.from_index {
        None => Cow::Borrowed(from.ty),
        Some(k) => Cow::Owned(element(from.ty, k, c.from_span)?),
    };
    let dest = match c.to_index {
        None => Cow::Borrowed(to.ty),
        Some(k) => Cow::Owned(element(to.ty, k, c.to_span)?),
    };
    if c.converts.len() > 4 {
        return Err(ConvertError {
            span: c.converts[4].span,
            message: "more than four <convert> steps".into(),
        });
    }
    for step in &c.converts {
        if let Some((k, span)) = step.index {
            t = Cow::Owned(element(&t, k, span)?);
        }
        if let Some((field, span)) = &step.field {
            t = Cow::Borrowed(field_type(ctx, &t, field, *span)?);
        }
        for (what, s) in [("scale", step.scale), ("offset", step.offset)] {
            if let Some((_, span)) = s {
                if !t.is_numeric() {
                    return Err(ConvertError {
                        span,
                        message: format!("`{what}` needs a number, but the value is `{t}`"),
                    });
                }
            }
        }
        if let Some((target, span)) = &step.to_type {
            let castable = (t.is_numeric() || *t == Type::Bool)
                && (target.is_numeric() || *target == Type::Bool);
            if !castable && *t != *target {
                return Err(ConvertError {
                    span: *span,
                    message: format!(
                        "`{t}` cannot be cast to `{target}`: casts convert between numbers"
                    ),
                });
            }
            t = Cow::Owned(target.clone());
        }
    }
    Ok((t, dest))
}

/// Element type of `t[k]`, or why `t` cannot be indexed there.
fn element(t: &Type, k: u32, span: Span) -> Result<Type, ConvertError> {
    match t {
        Type::Array(e, n) if k < *n => Ok((**e).clone()),
        Type::Array(_, n) => Err(ConvertError {
            span,
            message: format!("index {k} is out of bounds for `{t}` (length {n})"),
        }),
        Type::Seq(e) => Ok((**e).clone()),
        _ => Err(ConvertError {
            span,
            message: format!("`{t}` is not an array or sequence; it cannot be indexed"),
        }),
    }
}

/// Type of the field `field` of `t`, or why `t` has no such field.
fn field_type<'a>(
    ctx: &'a PassContext<'a>,
    t: &Type,
    field: &str,
    span: Span,
) -> Result<&'a Type, ConvertError> {
    let Type::Named(id, name) = t else {
        return Err(ConvertError {
            span,
            message: format!("`{t}` has no fields"),
        });
    };
    let nt = ctx.libraries.named_type(*id);
    match nt.fields.iter().find(|(f, _, _)| f == field) {
        Some((_, ft, _)) => Ok(ft),
        None => {
            let names: Vec<&str> = nt.fields.iter().map(|(f, _, _)| f.as_str()).collect();
            Err(ConvertError {
                span,
                message: format!(
                    "`{name}` has no field `{field}` (fields: {})",
                    names.join(", ")
                ),
            })
        }
    }
}

/// The unit of the value at the source, after a `field` step (fields carry units).
pub fn source_unit<'a>(
    ctx: &'a PassContext<'a>,
    c: &Connection,
    from: &PortView<'a>,
) -> Option<&'a ferroc_values::units::Unit> {
    let mut unit = from.unit;
    let mut t: &Type = from.ty;
    for step in &c.converts {
        if let Some((field, _)) = &step.field {
            if let Some((ft, fu)) = ctx.libraries.field_of(t, field) {
                unit = fu;
                t = ft;
            }
        }
    }
    unit
}

/// The units of both ends when both declare one: (source after `field` steps, destination).
pub fn unit_pair<'a>(
    ctx: &'a PassContext<'a>,
    c: &Connection,
    from: &PortView<'a>,
    to: &PortView<'a>,
) -> Option<(
    &'a ferroc_values::units::Unit,
    &'a ferroc_values::units::Unit,
)> {
    Some((source_unit(ctx, c, from)?, to.unit?))
}

/// `a/b/c → x/y/z` for messages.
pub fn describe(ctx: &PassContext<'_>, c: &Connection) -> String {
    format!(
        "{} → {}",
        ctx.sources.text(c.from_span),
        ctx.sources.text(c.to_span)
    )
}
