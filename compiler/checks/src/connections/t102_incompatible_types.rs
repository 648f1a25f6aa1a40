//! T102 `incompatible-types`: The types of the two ends are incompatible.
//!
//! The pass; the check's code, name and explanation are in `ferroc_model::checks`,
//! since the resolver raises it too.

use crate::PassContext;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};
pub use ferroc_model::checks::t102_incompatible_types::CHECK;
use ferroc_values::types::{compat, Compat, Type};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for (c, from, to) in ctx.connections_with_ends() {
        let Ok((value, dest)) = super::flow_types(ctx, c, from, to) else {
            continue;
        };
        if compat(&value, &dest) != Compat::Incompatible {
            continue;
        }
        out.push(
            Diagnostic::new(
                &CHECK,
                c.to_span,
                format!("cannot connect `{value}` to `{dest}`"),
            )
            .label(format!("expects `{dest}`"))
            .secondary(c.from_span, format!("sends `{value}`"))
            .secondary(to.span, format!("`{}` declared as `{}`", to.name, to.ty))
            .help(suggestion(ctx, &value, &dest)),
        );
    }
}

/// The conversion that would work, if one does.
fn suggestion(ctx: &PassContext<'_>, value: &Type, dest: &Type) -> String {
    if let Type::Named(id, name) = value {
        let fields = &ctx.libraries.named_type(*id).fields;
        if let Some((f, _, _)) = fields
            .iter()
            .find(|(_, t, _)| compat(t, dest) != Compat::Incompatible)
        {
            return format!(
                "take a field: <convert field=\"{f}\"/> (`{name}.{f}` is compatible with `{dest}`)"
            );
        }
    }
    if let Some(e) = value.element() {
        if compat(e, dest) != Compat::Incompatible {
            return "take one element: <convert index=\"0\"/>, or connect `port[i]`".to_string();
        }
    }
    if let Some(e) = dest.element() {
        if compat(value, e) != Compat::Incompatible {
            return "write into one element of the destination: `to=\"…/port[i]\"`".into();
        }
    }
    if value.is_numeric() && dest.is_numeric() {
        return format!("add <convert to-type=\"{dest}\"/>");
    }
    "connect ports of compatible types, or put a conversion module between them".into()
}
