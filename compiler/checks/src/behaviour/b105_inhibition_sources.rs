//! B105 `inhibition-sources`: An inhibition port has more than one source.

use super::{behaviours, is_inhibition, meta_inputs, port_path, sources};
use crate::{CheckInfo, PassContext};
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics, Severity};

pub static CHECK: CheckInfo = CheckInfo {
    code: "B105",
    name: "inhibition-sources",
    severity: Severity::Error,
    summary: "An inhibition port has more than one source.",
    explanation:
        "A behaviour combines its inhibitions as `i = max_k i_k`, one value per inhibition port. Two
sources into one port do not give the maximum: the port holds whichever value was written
last, so a strong inhibition can be overwritten by a weak one within the same cycle. Give
each inhibitor its own port; the instance parameter `inhibitions` sets how many there are.
Sources are counted at the module that really sends them, through group ports.

Bad:
    <module name=\"explore\" type=\"nav.Explore\"/>                <!-- inhibitions = 1 -->
    <connect from=\"avoid/activity\" to=\"explore/inhibition/0\"/>
    <connect from=\"dock/activity\" to=\"explore/inhibition/0\"/>

Fix:
    <module name=\"explore\" type=\"nav.Explore\">
      <param name=\"inhibitions\">2</param>
    </module>
    <connect from=\"avoid/activity\" to=\"explore/inhibition/0\"/>
    <connect from=\"dock/activity\" to=\"explore/inhibition/1\"/>",
    fixtures: "compiler/checks/src/behaviour/b105_inhibition_sources",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for (id, _, _) in behaviours(ctx) {
        let ports = meta_inputs(ctx, id)
            .filter(|(_, n)| is_inhibition(n))
            .count();
        for (input, name) in meta_inputs(ctx, id) {
            if !is_inhibition(name) {
                continue;
            }
            let found = sources(ctx.app, ctx.libraries, input);
            if found.len() < 2 {
                continue;
            }
            let path = format!("{}/{name}", ctx.app.path(id));
            let mut d = Diagnostic::new(
                &CHECK,
                found[1].last(ctx.app).to_span,
                format!(
                    "`{path}` has {} sources; an inhibition port takes one",
                    found.len()
                ),
            )
            .label("a second source arrives here");
            for s in &found {
                d = d.secondary(
                    s.first(ctx.app).from_span,
                    format!("source `{}`", port_path(ctx, s.port)),
                );
            }
            out.push(d.help(format!(
                "give each inhibitor its own port: set <param name=\"inhibitions\">{}</param> \
                 and connect every source to its own `inhibition/k` (the behaviour takes the \
                 maximum over its ports)",
                ports + found.len() - 1
            )));
        }
    }
}
