//! F109 `dependency-missing`: a component library used but missing from `dependencies`.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "F109",
    name: "dependency-missing",
    severity: Severity::Warning,
    summary: "An element's library is not listed in the file's `dependencies`.",
    explanation: "The root's `dependencies=\"libA, libB\"` lists the shared libraries FINROC loads
before creating the file's elements, and the libraries finroc_sync deploys with the
application. FINROC tries to load a missing library when it meets an unknown type, but
a deployment made from `dependencies` lacks it, and the element then fails to be
created on the robot (`No component type … available`) although it worked on the
developer's machine.

Bad:
    <Finstructable dependencies=\"finroc_projects_crash_course\">
      <element name=\"Control\" group=\"finroc_projects_crash_course_control\" type=\"Control\">

Fix: add the library to `dependencies`.",
    fixtures: "compiler/finroc/src/checks/f109_dependency_missing",
};

use super::Context;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};

pub fn check(ctx: &Context<'_>, out: &mut Diagnostics) {
    let mut reported = Vec::new();
    for (_, e) in ctx.doc.all_elements() {
        let Some(group) = &e.group else { continue };
        if ctx.doc.dependencies.iter().any(|d| d.text == group.text)
            || reported.contains(&group.text)
        {
            continue;
        }
        reported.push(group.text.clone());
        let mut d = Diagnostic::new(
            &CHECK,
            group.span,
            format!("`{}` is not in this file's `dependencies`", group.text),
        )
        .label("a deployment made from `dependencies` lacks this library");
        d = if ctx.doc.has_dependencies {
            d.secondary(
                ctx.doc
                    .dependencies
                    .first()
                    .map_or(ctx.doc.root_span, |x| x.span),
                "the dependencies",
            )
            .help(format!("add `{}` to `dependencies`", group.text))
        } else {
            d.help(format!(
                "add `dependencies=\"{}\"` to the root element",
                group.text
            ))
        };
        out.push(d);
    }
}
