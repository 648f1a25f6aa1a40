//! T110 `unused-output`: An output nobody reads.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};
use ferroc_model::ir::Endpoint;
use ferroc_model::library::{PortDir, PortRole};

pub static CHECK: CheckInfo = CheckInfo {
    code: "T110",
    name: "unused-output",
    severity: Severity::Note,
    summary: "An output nobody reads.",
    explanation:
        "An output with no connection is computed for nobody. Often that is fine (debug outputs);
sometimes a connection was forgotten.

Example:
    <module name=\"odom\" type=\"nav.Odometry\"/>   <!-- its output `pose` is not connected -->

Nothing to fix when intended; `--allow T110` hides these notes.",
    fixtures: "compiler/checks/src/connections/t110_unused_output",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for (id, _) in ctx.app.modules() {
        let unused: Vec<&str> = ctx
            .app
            .module_ports(ctx.libraries, id)
            .filter(|(k, p)| {
                let ep = Endpoint::Port {
                    element: id,
                    port: *k,
                };
                p.dir == PortDir::Out
                    && p.role != PortRole::Meta
                    && !ctx.app.has_outgoing(ep)
                    && !ctx.app.cut_off.contains(&ep)
                    && !ctx.app.ros2.binds(ep)
            })
            .map(|(_, p)| p.name.as_str())
            .collect();
        if unused.is_empty() {
            continue;
        }
        let element = ctx.app.element(id);
        let list = unused
            .iter()
            .map(|u| format!("`{u}`"))
            .collect::<Vec<_>>()
            .join(", ");
        out.push(
            Diagnostic::new(
                &CHECK,
                element.name_span,
                format!(
                    "output(s) {list} of `{}` are not connected",
                    ctx.app.path(id)
                ),
            )
            .label("computed for nobody")
            .help("connect them, or `--allow T110` when unused outputs are intended"),
        );
    }
}
