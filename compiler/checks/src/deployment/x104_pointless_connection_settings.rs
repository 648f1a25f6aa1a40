//! X104 `pointless-connection-settings`: Connection settings that have no effect where they are used.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};
use ferroc_diagnostics::source::Span;

pub static CHECK: CheckInfo = CheckInfo {
    code: "X104",
    name: "pointless-connection-settings",
    severity: Severity::Warning,
    summary: "Connection settings that have no effect where they are used.",
    explanation: "`sharing`, `reliability`, `min-interval` and `period` configure the transport between parts;
inside one part they do nothing. `period` needs `sharing=\"periodic\"`, `min-interval` goes
with `sharing=\"on-change\"`, and a periodic sample of a queue would drop queued items.

Bad:
    <connect from=\"robot/a/x/out\" to=\"robot/b/y/in\" reliability=\"reliable\"/>  <!-- same part -->

Fix: remove the setting, or correct the sharing mode.",
    fixtures: "compiler/checks/src/deployment/x104_pointless_connection_settings",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for c in &ctx.app.connections {
        let a = ctx.app.element(c.from.element()).part;
        let b = ctx.app.element(c.to.element()).part;
        let mut report = |span: Span, msg: String, help: &str| {
            out.push(
                Diagnostic::new(&CHECK, span, msg)
                    .label("has no effect")
                    .help(help.to_string()),
            );
        };
        if a == b {
            let settings = [
                ("sharing", c.sharing().map(|s| s.1)),
                ("reliability", c.reliability()),
                ("min-interval", c.min_interval()),
                ("period", c.period()),
                ("deadline", c.deadline()),
            ];
            for (name, span) in settings {
                if let Some(span) = span {
                    report(span, format!("`{name}` configures transport between parts, but both ends are in one part"), "remove it, or move one end into another part");
                }
            }
            continue;
        }
        let sharing = c
            .sharing()
            .as_ref()
            .map(|s| s.0.as_str())
            .unwrap_or("on-change");
        if let Some(span) = c.period() {
            if sharing != "periodic" {
                report(
                    span,
                    "`period` only applies with sharing=\"periodic\"".into(),
                    "add sharing=\"periodic\" or remove `period`",
                );
            } else if c.queue.is_some() {
                report(
                    span,
                    "a periodic sample of a queue would drop queued items".into(),
                    "use sharing=\"on-change\" for queues",
                );
            }
        }
        if let (Some(span), "periodic") = (c.min_interval(), sharing) {
            report(
                span,
                "`min-interval` only applies with sharing=\"on-change\"".into(),
                "remove `min-interval`, or use sharing=\"on-change\"",
            );
        }
    }
}
