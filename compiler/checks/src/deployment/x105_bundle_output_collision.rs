//! X105 `bundle-output-collision`: Two parts would write the same files in a bundle.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};
use ferroc_diagnostics::source::Span;
use ferroc_model::ir::ElementKind;
use hashbrown::HashMap;

pub static CHECK: CheckInfo = CheckInfo {
    code: "X105",
    name: "bundle-output-collision",
    severity: Severity::Error,
    summary: "Two parts would write the same files in a bundle.",
    explanation:
        "Each part becomes a binary crate, a systemd unit and a launch entry named after it. Names
that differ only in letter case collide on case-insensitive file systems and in unit names.

Bad:
    <part name=\"Robot\"/> <part name=\"robot\"/>

Fix: give the parts names that differ in more than case.",
    fixtures: "compiler/checks/src/deployment/x105_bundle_output_collision",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    let mut seen: HashMap<String, (&str, Span)> = HashMap::new();
    for e in &ctx.app.elements {
        if !matches!(e.kind, ElementKind::Part { .. }) {
            continue;
        }
        let key = e.name.to_ascii_lowercase();
        match seen.get(&key) {
            Some((first, span)) => out.push(
                Diagnostic::new(
                    &CHECK,
                    e.name_span,
                    format!(
                        "part `{}` and part `{first}` would write the same bundle files",
                        e.name
                    ),
                )
                .label("collides")
                .secondary(*span, "the other part")
                .help("give the parts names that differ in more than letter case"),
            ),
            None => {
                seen.insert(key, (e.name.as_str(), e.name_span));
            }
        }
    }
}
