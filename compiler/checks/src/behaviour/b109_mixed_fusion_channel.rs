//! B109 `mixed-fusion-channel`: A fusion channel's activity, target rating and data come
//! from different behaviours.

use super::{behaviour_unit, behaviours, channels, characteristic_groups, list, sources};
use crate::{CheckInfo, PassContext};
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics, Severity};
use ferroc_diagnostics::source::Span;
use ferroc_model::ir::{ElementId, ElementKind};

pub static CHECK: CheckInfo = CheckInfo {
    code: "B109",
    name: "mixed-fusion-channel",
    severity: Severity::Error,
    summary: "A fusion channel's activity, target rating and data come from different behaviours.",
    explanation:
        "A fusion behaviour picks or weighs each channel's data by that channel's activity. If a
channel's activity comes from one behaviour and its data from another, the fusion hands
control to a behaviour that did not ask for it: obstacle avoidance's turn rate weighted
with goal following's (high) activity steers the robot while the avoider itself is
inactive. Each channel's activity, target rating and data must come from one behaviour.
Sources are followed through group ports; an iB2C group (one with a characteristic
behaviour) counts as one behaviour from outside, since its activity and its data outputs
belong together. Data coming from a module that is not a behaviour (a filter, a
converter) is not judged. The odd one out is reported: the connection that disagrees with
the others of its channel.

Bad:
    <connect from=\"avoid/activity\" to=\"fusion/in/0/activity\"/>
    <connect from=\"follow/target_rating\" to=\"fusion/in/0/target_rating\"/>
    <connect from=\"follow/velocity\" to=\"fusion/in/0/velocity\"/>

Fix:
    <connect from=\"follow/activity\" to=\"fusion/in/0/activity\"/>",
    fixtures: "compiler/checks/src/behaviour/b109_mixed_fusion_channel",
};

/// One port of a channel fed by a behaviour: (port name, behaviour, first hop's source span).
type Entry<'a> = (&'a str, ElementId, Span);

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    let groups = characteristic_groups(ctx.app);
    for (id, _, mt) in behaviours(ctx) {
        let path = ctx.app.path(id);
        for channel in channels(ctx, id, mt) {
            // Data ports first, then target rating, then activity: on a tie, the behaviour
            // that sends the data defines the channel.
            let mut entries: Vec<Entry<'_>> = Vec::new();
            for &(port, name) in channel.ports.iter().rev() {
                for s in sources(ctx.app, ctx.libraries, port) {
                    let is_behaviour = ctx
                        .app
                        .module_type(ctx.libraries, s.module)
                        .is_some_and(|t| t.is_behaviour());
                    let unit = behaviour_unit(ctx.app, &groups, s.module, id);
                    if is_behaviour || unit != s.module {
                        let shown = &ctx.app.connections[s.outermost_hop(ctx.app)];
                        entries.push((name, unit, shown.from_span));
                    }
                }
            }
            let mut votes: Vec<(ElementId, usize)> = Vec::new();
            for &(_, unit, _) in &entries {
                match votes.iter_mut().find(|(u, _)| *u == unit) {
                    Some((_, n)) => *n += 1,
                    None => votes.push((unit, 1)),
                }
            }
            if votes.len() < 2 {
                continue;
            }
            // The first behaviour with the most votes (max_by_key would take the last).
            let Some(best) = votes.iter().map(|(_, n)| *n).max() else {
                continue;
            };
            let Some(&(reference, _)) = votes.iter().find(|(_, n)| *n == best) else {
                continue;
            };
            let odd: Vec<&Entry<'_>> = entries.iter().filter(|e| e.1 != reference).collect();
            let agree: Vec<&Entry<'_>> = entries.iter().filter(|e| e.1 == reference).collect();
            let Some(&&(odd_name, odd_unit, odd_span)) =
                odd.iter().min_by_key(|e| (e.2.file, e.2.start))
            else {
                continue;
            };
            let k = channel.k;
            let (a, b) = (describe(ctx, reference), describe(ctx, odd_unit));
            let agreeing: Vec<&str> = agree.iter().rev().map(|e| e.0).collect();
            let mut d = Diagnostic::new(
                &CHECK,
                odd_span,
                format!(
                    "fusion channel {k} of `{path}` mixes behaviours: its `{odd_name}` comes from {b}, its {} from {a}",
                    list(&agreeing)
                ),
            )
            .label(format!("{b}, not {a}"));
            for e in odd.iter().filter(|e| e.2 != odd_span) {
                d = d.secondary(
                    e.2,
                    format!("channel {k}'s `{}` from {}", e.0, describe(ctx, e.1)),
                );
            }
            for e in agree.iter().rev() {
                d = d.secondary(e.2, format!("channel {k}'s `{}` from {a}", e.0));
            }
            out.push(d.help(format!(
                "connect `{path}/in/{k}/{odd_name}` from {a} as well (the fusion weighs each \
                 channel's data by that channel's activity), or give {b} a channel of its own"
            )));
        }
    }
}

/// "`robot/main/avoid`", or "iB2C group `robot/main/nav`".
fn describe(ctx: &PassContext<'_>, unit: ElementId) -> String {
    match ctx.app.element(unit).kind {
        ElementKind::Group => format!("iB2C group `{}`", ctx.app.path(unit)),
        _ => format!("`{}`", ctx.app.path(unit)),
    }
}
