//! F113 `parameter-link-target-missing`: a parameter link names no parameter.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "F113",
    name: "parameter-link-target-missing",
    severity: Severity::Warning,
    summary: "A parameter link (`<parameter link>`, `<parameter_links>`) names an element or parameter that does not exist.",
    explanation: "A link ties a parameter, named by its path below the group
(`Simulation/AddNoise Front/Parameters/Standard Deviation`), to a config entry or a
command-line option. FINROC looks the parameter up when it loads the file and logs
`Cannot find parameter` when the path leads nowhere: the config entry and the option
then configure nothing, silently. The path's elements are those the file creates, those
a group's C++ constructor creates (catalogue) and those its group file adds; the
parameter names are the catalogue's. Paths through types not in the catalogue are not
judged.

Bad (AddNoise's parameter is Standard Deviation):
    <parameter link=\"Simulation/AddNoise Front/Parameters/Sigma\" config=\"/noiselevel\"/>

Fix: write the path FINROC shows in finstruct (Element/…/Parameters/Name).",
    fixtures: "compiler/finroc/src/checks/f113_parameter_link_target_missing",
};

use super::Context;
use crate::catalogue::Component;
use crate::finstructable::Element;
use ferroc_diagnostics::diagnostic::{did_you_mean, Diagnostic, Diagnostics};

/// Where a link path leads.
pub enum Target {
    /// The parameter (its FINROC name and unit).
    Param(String, Option<String>),
    Missing(String, Option<String>),
    Unknown,
}

/// The elements directly inside an element of type `c`: the file's nested elements,
/// what the constructor builds, what its group file adds.
fn inside<'a>(ctx: &'a Context<'_>, e: &'a Element, c: &'a Component) -> (Vec<&'a Element>, bool) {
    let mut list: Vec<&Element> = e.children.iter().collect();
    if let Some(content) = &c.content {
        list.extend(content.elements.iter());
    }
    let file = e
        .xml_file()
        .map(|p| p.value.text.trim().to_string())
        .or_else(|| c.xml_file.clone());
    let mut complete = !c.open;
    match file.as_deref().map(|f| ctx.checkout.group_file(f)) {
        Some(Some(g)) => list.extend(g.doc.elements.iter()),
        Some(None) => complete = false, // its group file is not in the checkout
        None => {}
    }
    (list, complete)
}

pub fn resolve(ctx: &Context<'_>, path: &[String]) -> Target {
    let Some((name, elements)) = path.split_last() else {
        return Target::Unknown;
    };
    let mut list: Vec<&Element> = ctx.doc.elements.iter().collect();
    let mut complete = true;
    let mut component: Option<&Component> = None;
    let mut owner_name = "this file".to_string();
    for seg in elements.iter().filter(|s| *s != "Parameters") {
        let Some(e) = list.iter().copied().find(|e| &e.name.text == seg) else {
            if !complete {
                return Target::Unknown;
            }
            let near =
                did_you_mean(seg, list.iter().map(|e| e.name.text.as_str())).map(str::to_string);
            return Target::Missing(format!("there is no element `{seg}` in {owner_name}"), near);
        };
        let (Some(g), Some(t)) = (&e.group, &e.ty) else {
            return Target::Unknown;
        };
        let Some(c) = ctx.catalogue.get(&g.text, &t.text) else {
            return Target::Unknown;
        };
        (list, complete) = inside(ctx, e, c);
        component = Some(c);
        owner_name = format!("`{}` (`{}`)", e.name.text, t.text);
    }
    let Some(c) = component else {
        return Target::Unknown;
    };
    match c.param(name) {
        Some((n, u)) => Target::Param(n.clone(), u.clone()),
        None if c.composite || c.open => Target::Unknown,
        None => {
            let near =
                did_you_mean(name, c.params.iter().map(|(n, _)| n.as_str())).map(str::to_string);
            Target::Missing(format!("{owner_name} has no parameter `{name}`"), near)
        }
    }
}

pub fn check(ctx: &Context<'_>, out: &mut Diagnostics) {
    for link in &ctx.doc.links {
        if let Target::Missing(why, near) = resolve(ctx, &link.path) {
            let d = Diagnostic::new(
                &CHECK,
                link.path_span,
                format!("`{}` leads to no parameter: {why}", link.path.join("/")),
            )
            .label("FINROC logs `Cannot find parameter`; the link configures nothing");
            out.push(match near {
                Some(n) => d.help(format!("did you mean `{n}`?")),
                None => d.help(
                    "write the parameter's path as finstruct shows it: Element/…/Parameters/Name",
                ),
            });
        }
    }
}
