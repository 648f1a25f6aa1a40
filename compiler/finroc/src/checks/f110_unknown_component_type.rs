//! F110 `unknown-component-type`: an element's type is not in the catalogue.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "F110",
    name: "unknown-component-type",
    severity: Severity::Note,
    summary: "An element's component type is not in ferroc's FINROC catalogue; checks needing it are skipped.",
    explanation: "A FINROC file names a component type by library and create-action name
(`group=\"finroc_projects_crash_course\" type=\"AddNoise\"`); its ports, types and units
are in the C++ sources, which ferroc knows through its catalogue (components/finroc/).
For a type not in the catalogue, edge ends into it, type and unit comparisons and
parameter units cannot be checked; this note says so once per element, and `ferroc
check` lists the skipped edge ends.

Example:
    <element name=\"Laser\" group=\"finroc_libraries_sick\" type=\"LMS\"/>

Fix: nothing in the FINROC file. Add the type to the catalogue (a manifest in
components/finroc/) to have it checked.",
    fixtures: "compiler/finroc/src/checks/f110_unknown_component_type",
};

use super::Context;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};

pub fn check(ctx: &Context<'_>, out: &mut Diagnostics) {
    for (path, e) in ctx.doc.all_elements() {
        let (Some(group), Some(ty)) = (&e.group, &e.ty) else {
            continue;
        };
        if ctx.catalogue.get(&group.text, &ty.text).is_some() {
            continue;
        }
        out.push(
            Diagnostic::new(
                &CHECK,
                ty.span,
                format!(
                    "`{}` in `{}` is not in ferroc's FINROC catalogue",
                    ty.text, group.text
                ),
            )
            .label(format!("edges into `{path}` are not checked"))
            .help("describe the type in a manifest under components/finroc/ to have it checked"),
        );
    }
}
