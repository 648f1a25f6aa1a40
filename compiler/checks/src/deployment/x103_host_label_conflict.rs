//! X103 `host-label-conflict`: Host labels that differ only in letter case.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};
use ferroc_diagnostics::source::Span;
use ferroc_model::ir::ElementKind;
use hashbrown::HashMap;

pub static CHECK: CheckInfo = CheckInfo {
    code: "X103",
    name: "host-label-conflict",
    severity: Severity::Warning,
    summary: "Host labels that differ only in letter case.",
    explanation:
        "Host names are case-insensitive, so `Robot-PC` and `robot-pc` are one machine, yet the
bundle would treat them as two. Usually one of them is a typo.

Bad:
    <part name=\"a\" host=\"Robot-PC\"/>
    <part name=\"b\" host=\"robot-pc\"/>

Fix: write the host label the same way everywhere.",
    fixtures: "compiler/checks/src/deployment/x103_host_label_conflict",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    let mut seen: HashMap<String, (&str, Span)> = HashMap::new();
    for e in &ctx.app.elements {
        let ElementKind::Part {
            host: Some((host, span)),
        } = &e.kind
        else {
            continue;
        };
        match seen.get(&host.to_ascii_lowercase()) {
            Some((first, first_span)) if *first != host.as_str() => out.push(
                Diagnostic::new(
                    &CHECK,
                    *span,
                    format!("host `{host}` differs from `{first}` only in letter case"),
                )
                .label("same host, other spelling")
                .secondary(*first_span, "first spelling")
                .help(format!(
                    "write `{first}` here too (host names are case-insensitive)"
                )),
            ),
            Some(_) => {}
            None => {
                seen.insert(host.to_ascii_lowercase(), (host.as_str(), *span));
            }
        }
    }
}
