//! B103 `never-stimulated`: A behaviour in stimulation mode `auto` has nothing feeding its
//! stimulation, so it can never become active.

use super::{behaviours, sources, stimulation_mode, Mode};
use crate::{CheckInfo, PassContext};
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics, Severity};
use ferroc_model::ir::Endpoint;

pub static CHECK: CheckInfo = CheckInfo {
    code: "B103",
    name: "never-stimulated",
    severity: Severity::Warning,
    summary: "A behaviour in stimulation mode `auto` has an unconnected stimulation and can never become active.",
    explanation:
        "A behaviour's activation is `ι = s · (1 − i)`. In stimulation mode `auto` (the default)
`s` is what arrives at its `stimulation` input; with nothing connected it stays 0, so the
behaviour's activity — and its influence on any fusion — is 0 forever. FINROC only notices at
run time (\"Stimulation mode is AUTO but stimulation port not connected. Activation is
zero.\"). A stimulation connected only to a group port that nothing feeds counts as
unconnected.

Bad:
    <module name=\"follow_wall\" type=\"nav.FollowWall\"/>   <!-- nothing into follow_wall/stimulation -->

Fix: connect an activity (another behaviour's, or a `ferroc_std.ConstantActivity`) to the
stimulation, or say that the behaviour is always stimulated:
    <module name=\"follow_wall\" type=\"nav.FollowWall\">
      <param name=\"stimulation_mode\">enabled</param>
    </module>",
    fixtures: "compiler/checks/src/behaviour/b103_never_stimulated",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for (id, m, mt) in behaviours(ctx) {
        let Some((Mode::Auto, given)) = stimulation_mode(m) else {
            continue;
        };
        let Some(&port) = mt.port_index.get("stimulation") else {
            continue;
        };
        let input = Endpoint::Port {
            element: id,
            port: port as u32,
        };
        if !sources(ctx.app, ctx.libraries, input).is_empty() || ctx.app.cut_off.contains(&input) {
            continue;
        }
        let path = ctx.app.path(id);
        let element = ctx.app.element(id);
        let mut d = match given {
            Some(span) => Diagnostic::new(&CHECK, span, "")
                .label("`auto`: activation follows the stimulation input")
                .secondary(element.name_span, "this behaviour"),
            None => Diagnostic::new(&CHECK, element.name_span, "")
                .label("stimulation mode `auto` (the default)"),
        };
        d.message =
            format!("behaviour `{path}` can never become active: its stimulation is not connected");
        for c in ctx.app.incoming(input) {
            d = d.secondary(
                c.to_span,
                format!(
                    "connected only to `{}`, which nothing feeds",
                    ctx.sources.text(c.from_span)
                ),
            );
        }
        if let Some(at) = element.instantiated_at {
            d = d.secondary(at, "in this group instance");
        }
        out.push(d.help(format!(
            "connect an activity to `{path}/stimulation`, or set \
             <param name=\"stimulation_mode\">enabled</param> if it should always be stimulated"
        )));
    }
}
