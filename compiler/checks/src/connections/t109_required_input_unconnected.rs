//! T109 `required-input-unconnected`: An input declared `required="true"` has no connection.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};
use ferroc_model::ir::Endpoint;
use ferroc_model::library::PortDir;

pub static CHECK: CheckInfo = CheckInfo {
    code: "T109",
    name: "required-input-unconnected",
    severity: Severity::Error,
    summary: "An input declared `required=\"true\"` has no connection.",
    explanation: "A module type declares `required=\"true\"` on inputs it cannot work without. Such a module
would wait or compute garbage forever.

Bad:
    <module name=\"loc\" type=\"nav.Localizer\"/>   <!-- its required input `scan` is never connected -->

Fix: connect the input.",
    fixtures: "compiler/checks/src/connections/t109_required_input_unconnected",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for (id, m) in ctx.app.modules() {
        for (k, port) in ctx.app.module_ports(ctx.libraries, id) {
            if !port.required || port.dir != PortDir::In {
                continue;
            }
            let ep = Endpoint::Port {
                element: id,
                port: k,
            };
            if ctx.app.node(ep).is_some() && ctx.app.incoming(ep).next().is_some()
                || ctx.app.cut_off.contains(&ep)
            {
                continue;
            }
            let element = ctx.app.element(id);
            let mut d = Diagnostic::new(
                &CHECK,
                element.name_span,
                format!(
                    "required input `{}` of `{}` is not connected",
                    port.name,
                    ctx.app.path(id)
                ),
            )
            .label(format!("`{}` needs `{}`", element.name, port.name))
            .secondary(port.span, "declared required here");
            if let Some(at) = element.instantiated_at {
                d = d.secondary(at, "in this instance");
            }
            let _ = m;
            out.push(d.help(format!(
                "add <connect from=\"…\" to=\"{}/{}\"/>",
                element.name, port.name
            )));
        }
    }
}
