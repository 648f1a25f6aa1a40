//! T111 `not-serialisable-across-parts`: A connection between parts carries a type that cannot be serialised.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};

pub static CHECK: CheckInfo = CheckInfo {
    code: "T111",
    name: "not-serialisable-across-parts",
    severity: Severity::Error,
    summary: "A connection between parts carries a type that cannot be serialised.",
    explanation: "Parts are separate processes, possibly on separate hosts: data between them is serialised.
A library type declared without `serde=\"true\"` cannot cross. For a call between parts
that holds for the request and for the response type.

Bad:
    <connect from=\"robot/main/cam/image_view\" to=\"station/ui/viewer/image\"/>  <!-- type has serde=\"false\" -->

Fix: connect a serialisable type, or move both modules into one part.",
    fixtures: "compiler/checks/src/connections/t111_not_serialisable_across_parts",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for (c, from, _) in ctx.connections_with_ends() {
        let a = ctx.app.element(c.from.element()).part;
        let b = ctx.app.element(c.to.element()).part;
        if a == b || a.is_none() || b.is_none() {
            continue;
        }
        // A call between parts sends its answer back: the response type crosses too.
        if from.role == ferroc_model::library::PortRole::Client
            && ctx.libraries.serialisable(from.ty)
        {
            let response = (ctx.app.module_type(ctx.libraries, c.from.element()))
                .and_then(|ty| ty.clients.iter().find(|k| k.name == from.name))
                .and_then(|k| k.response.as_ref().map(|r| (r, k.span)));
            if let Some((response, span)) = response.filter(|(r, _)| !ctx.libraries.serialisable(r))
            {
                out.push(
                    Diagnostic::new(&CHECK, c.span, format!("`{}` calls from part `{}` to part `{}`, but its response type `{response}` cannot be serialised", super::describe(ctx, c), ctx.app.path(a.unwrap_or(c.scope)), ctx.app.path(b.unwrap_or(c.scope))))
                        .label("the answer comes back between two processes")
                        .secondary(span, format!("`{}` declares response=\"{response}\"", from.name))
                        .help("declare the type with serde=\"true\" in its manifest (and implement serde for it), or keep both modules in one part"),
                );
            }
            continue;
        }
        if ctx.libraries.serialisable(from.ty) {
            continue;
        }
        out.push(
            Diagnostic::new(&CHECK, c.span, format!("`{}` crosses from part `{}` to part `{}`, but `{}` cannot be serialised", super::describe(ctx, c), ctx.app.path(a.unwrap_or(c.scope)), ctx.app.path(b.unwrap_or(c.scope)), from.ty))
                .label("between two processes")
                .secondary(from.span, format!("`{}` has type `{}`", from.name, from.ty))
                .help("declare the type with serde=\"true\" in its manifest (and implement serde for it), or keep both modules in one part"),
        );
    }
}
