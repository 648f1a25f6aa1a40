//! F112 `library-not-built`: a library of the checkout that no make.xml of it builds.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "F112",
    name: "library-not-built",
    severity: Severity::Error,
    summary: "A `dependencies` entry or element `group` names a library of this checkout that no make.xml builds.",
    explanation: "An application names shared libraries by their build names: `dependencies`
lists what FINROC loads before creating elements, each element's `group` the library
registering its type. The libraries of the checkout itself are built by its make.xml
files, with names formed from the folder (`finroc_projects_crash_course`) and the target
(`…_control`). A name with the checkout's own prefix that no make.xml builds is a
misspelling or a stale name: FINROC logs
`Dependency … is not available` and cannot create the elements (`No component type … in
'lib….so'`). Names of other repositories (plugins, rrlib) are not judged.

Bad (the make.xml builds finroc_projects_crash_course_control):
    <Finstructable dependencies=\"finroc_projects_crash_course_controll\">

Fix: use the name the make.xml builds (see the help), or add the target.",
    fixtures: "compiler/finroc/src/checks/f112_library_not_built",
};

use super::Context;
use ferroc_diagnostics::diagnostic::{did_you_mean, Diagnostic, Diagnostics};

pub fn check(ctx: &Context<'_>, out: &mut Diagnostics) {
    let built = &ctx.checkout.built;
    if built.is_empty() {
        return;
    }
    let mut names: Vec<&crate::finstructable::Named> = ctx.doc.dependencies.iter().collect();
    let elements = ctx.doc.all_elements();
    names.extend(elements.iter().filter_map(|(_, e)| e.group.as_ref()));
    let mut reported: Vec<&str> = Vec::new();
    for name in names {
        let n = name.text.as_str();
        if built.iter().any(|b| b == n) || reported.contains(&n) {
            continue;
        }
        if !ctx
            .checkout
            .prefixes
            .iter()
            .any(|p| n.starts_with(p.as_str()))
        {
            continue; // another repository's library: not judged
        }
        let near = did_you_mean(n, built.iter().map(String::as_str));
        reported.push(n);
        let help = match near {
            Some(b) => format!("did you mean `{b}`?"),
            None => format!("the make.xml files here build {}", built.join(", ")),
        };
        out.push(
            Diagnostic::new(
                &CHECK,
                name.span,
                format!("no make.xml of this checkout builds `{n}`"),
            )
            .label("FINROC cannot load this library")
            .help(help),
        );
    }
}
