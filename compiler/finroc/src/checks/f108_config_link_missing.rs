//! F108 `config-link-missing`: a parameter linked to a config entry no config file has.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "F108",
    name: "config-link-missing",
    severity: Severity::Error,
    summary: "A parameter is linked to a config entry that no config file of the checkout has.",
    explanation: "A `<parameter link=\"…\" config=\"/node/value\"/>` (or its `<parameter_links>`
form) makes FINROC load the parameter from that entry of the application's config
file. When the entry does not exist FINROC keeps the parameter's default without an
error, so a misspelt path silently runs the robot with other values than the team
configured. ferroc looks in every config file (root `<root>`) of the checkout; when the
checkout has none the links are listed as not checked.

Bad:
    <parameter link=\"Simulation/AddNoise Rear/Parameters/Standard Deviation\" config=\"/noise_level\"/>
    (the config file has <value name=\"noiselevel\">)

Fix: write the entry's path as the config file nests it (`/node/…/value`).",
    fixtures: "compiler/finroc/src/checks/f108_config_link_missing",
};

use super::Context;
use ferroc_diagnostics::diagnostic::{did_you_mean, Diagnostic, Diagnostics};

pub fn check(ctx: &Context<'_>, out: &mut Diagnostics, not_checked: &mut Vec<String>) {
    let linked: Vec<_> = ctx
        .doc
        .links
        .iter()
        .filter_map(|l| l.config.as_ref())
        .collect();
    if linked.is_empty() {
        return;
    }
    if ctx.checkout.configs.is_empty() {
        not_checked.push(format!(
            "{}: {} config link(s) not checked: no config file (root <root>) under {}",
            ctx.path.display(),
            linked.len(),
            ctx.checkout.root.display()
        ));
        return;
    }
    let all: Vec<&str> = ctx
        .checkout
        .configs
        .iter()
        .flat_map(|c| c.entries.iter().map(|e| e.path.as_str()))
        .collect();
    for config in linked {
        if ctx.checkout.config_entry(&config.text).is_some() {
            continue;
        }
        let files: Vec<String> = ctx
            .checkout
            .configs
            .iter()
            .map(|c| ctx.sources.get(c.file).name.clone())
            .collect();
        let mut d = Diagnostic::new(
            &CHECK,
            config.span,
            format!("no config file has the entry `{}`", config.text),
        )
        .label("FINROC keeps the parameter's default");
        d = match did_you_mean(&config.text, all.iter().copied()) {
            Some(s) => d.help(format!(
                "did you mean `{s}`? (looked in {})",
                files.join(", ")
            )),
            None => d.help(format!(
                "add the entry, or fix the path (looked in {})",
                files.join(", ")
            )),
        };
        out.push(d);
    }
}

/// The FINROC name and unit of the parameter a link path names, when the catalogue
/// knows it: `Simulation/MainSimulation/Parameters/Destructive Collision Speed`.
pub fn linked_param_unit(ctx: &Context<'_>, path: &[String]) -> Option<(String, String)> {
    match super::f113_parameter_link_target_missing::resolve(ctx, path) {
        super::f113_parameter_link_target_missing::Target::Param(n, Some(u)) => Some((n, u)),
        _ => None,
    }
}
