//! B106 `self-inhibition`: A behaviour inhibits itself.

use super::{behaviours, is_inhibition, meta_inputs, sources};
use crate::{CheckInfo, PassContext};
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics, Severity};

pub static CHECK: CheckInfo = CheckInfo {
    code: "B106",
    name: "self-inhibition",
    severity: Severity::Error,
    summary: "A behaviour's own activity feeds one of its inhibition ports.",
    explanation: "A behaviour whose activity (or a derived activity) inhibits itself computes
`ι = s · (1 − a)` from its own output: the more it acts, the less it may act. Depending on
the order of updates it oscillates between full and no activity, or settles where it
barely acts at all — never what the network was designed for. The connection is found
directly or through group ports (for example an iB2C group whose `activity` output is wired
back into its own `inhibition` input). Mutual inhibition between two competing behaviours
is the normal iB2C pattern and is not this error.

Bad:
    <connect from=\"avoid/activity\" to=\"avoid/inhibition/0\"/>

Fix: remove the connection. To make behaviours take turns, let each inhibit the other
(`a/activity → b/inhibition/0`, `b/activity → a/inhibition/0`).",
    fixtures: "compiler/checks/src/behaviour/b106_self_inhibition",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for (id, _, _) in behaviours(ctx) {
        for (input, name) in meta_inputs(ctx, id) {
            if !is_inhibition(name) {
                continue;
            }
            for s in sources(ctx.app, ctx.libraries, input) {
                if s.module != id {
                    continue;
                }
                let own = ctx
                    .app
                    .view(ctx.libraries, s.port)
                    .map_or("activity", |v| v.name);
                let path = ctx.app.path(id);
                let short = &ctx.app.element(id).name;
                let d = if s.route.len() == 1 {
                    let c = s.first(ctx.app);
                    Diagnostic::new(
                        &CHECK,
                        c.from_span,
                        format!("behaviour `{path}` inhibits itself"),
                    )
                    .label(format!("its own `{own}`"))
                    .secondary(c.to_span, format!("into its own `{name}`"))
                } else {
                    // Through group ports: blame the hop that closes the loop (declared
                    // in the outermost scope), and show the way around.
                    let closing = s.outermost_hop(ctx.app);
                    let c = &ctx.app.connections[closing];
                    let mut d = Diagnostic::new(
                        &CHECK,
                        c.from_span,
                        format!("behaviour `{path}` inhibits itself through group ports"),
                    )
                    .label(format!(
                        "routes `{short}`'s own `{own}` back into its `{name}`"
                    ));
                    for &hop in &s.route {
                        if hop == closing {
                            continue;
                        }
                        let h = &ctx.app.connections[hop];
                        let (span, text) = if hop == s.first {
                            (h.from_span, format!("`{short}/{own}` leaves here"))
                        } else if hop == s.last {
                            (h.to_span, format!("and enters `{short}/{name}` here"))
                        } else {
                            (h.from_span, "passes here".to_string())
                        };
                        d = d.secondary(span, text);
                    }
                    d
                };
                out.push(d.help(
                    "remove the connection that feeds the behaviour's activity back; to make \
                     behaviours take turns, let competitors inhibit each other instead",
                ));
            }
        }
    }
}
