//! M112 `module-not-executed`: A module with no thread container above it never runs.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};

pub static CHECK: CheckInfo = CheckInfo {
    code: "M112",
    name: "module-not-executed",
    severity: Severity::Error,
    summary: "A module with no thread container above it never runs.",
    explanation: "A module is executed by the nearest thread container above it. A module placed directly in a
part (or in a group that is not inside a thread) would be instantiated and never updated.

Bad:
    <part name=\"robot\">
      <module name=\"laser\" type=\"nav.LaserDriver\"/>
    </part>

Fix: put it in a thread container: `<thread name=\"main\" period=\"10ms\"> ... </thread>`.",
    fixtures: "compiler/checks/src/model/m112_module_not_executed",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for (id, _) in ctx.app.modules() {
        let element = ctx.app.element(id);
        if element.thread.is_some() {
            continue;
        }
        let mut d = Diagnostic::new(
            &CHECK,
            element.name_span,
            format!(
                "module `{}` is not inside any thread container, so it never runs",
                ctx.app.path(id)
            ),
        )
        .label("no <thread> above this module");
        if let Some(at) = element.instantiated_at {
            d = d.secondary(at, "in this instance");
        }
        out.push(
            d.help("move it (or its group) into a <thread name=\"…\" period=\"10ms\"> of its part"),
        );
    }
}
