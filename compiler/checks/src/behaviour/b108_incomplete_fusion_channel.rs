//! B108 `incomplete-fusion-channel`: A fusion channel lacks its activity, target rating or
//! data.

use super::{behaviours, channels, list, param_span, sources};
use crate::{CheckInfo, PassContext};
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics, Severity};
use ferroc_diagnostics::source::Span;

pub static CHECK: CheckInfo = CheckInfo {
    code: "B108",
    name: "incomplete-fusion-channel",
    severity: Severity::Error,
    summary: "A fusion channel is not fully connected (activity, target rating and data).",
    explanation:
        "A fusion behaviour weighs each channel's data by that channel's activity (and fuses the
target ratings the same way). A channel without its activity, target rating or any of its
data inputs cannot take part — and FINROC's fusion does not degrade gracefully: it logs
\"… is not connected.\", refuses to process its transfer function and publishes nothing
at all that cycle, for any channel. The instance parameter `channels` says how many
channels there are (default 2); every one of them needs `in/k/activity`,
`in/k/target_rating` and each `in/k/<data>` connected (through group ports if need be).

Bad:
    <module name=\"fusion\" type=\"nav.VelocityFusion\">
      <param name=\"channels\">2</param>
    </module>
    <connect from=\"follow/activity\" to=\"fusion/in/0/activity\"/>
    <connect from=\"follow/velocity\" to=\"fusion/in/0/velocity\"/>
    <!-- no fusion/in/0/target_rating, nothing into channel 1 -->

Fix: connect the missing ports from the channel's behaviour, or lower `channels` to the
number of behaviours actually fused.",
    fixtures: "compiler/checks/src/behaviour/b108_incomplete_fusion_channel",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for (id, m, mt) in behaviours(ctx) {
        let path = ctx.app.path(id);
        let element = ctx.app.element(id);
        let declared = param_span(m, "channels");
        let count_at = declared.unwrap_or(element.name_span);
        let all = channels(ctx, id, mt);
        let mut empty = Vec::new();
        for channel in &all {
            let mut missing = Vec::new();
            let mut present = Vec::new();
            for &(port, name) in &channel.ports {
                match sources(ctx.app, ctx.libraries, port).first() {
                    Some(s) => present.push((s.last(ctx.app).to_span, name)),
                    None => missing.push(name),
                }
            }
            if missing.is_empty() {
                continue;
            }
            let k = channel.k;
            let Some(&first) = present.iter().min_by_key(|(s, _)| (s.file, s.start)) else {
                empty.push(k);
                continue;
            };
            let mut d = partly_connected(&path, k, &missing, &present, first);
            d = d.secondary(count_at, format!("{} channel(s)", all.len()));
            out.push(d.help(format!(
                "connect {} from the behaviour whose activity feeds channel {k} (the fusion \
                 publishes nothing while a channel is incomplete)",
                missing
                    .iter()
                    .map(|n| format!("`{path}/in/{k}/{n}`"))
                    .collect::<Vec<_>>()
                    .join(", ")
            )));
        }
        if empty.is_empty() {
            continue;
        }
        let mut d = unconnected(&path, &empty, all.len(), count_at, declared.is_some());
        if declared.is_some() {
            d = d.secondary(element.name_span, "this fusion");
        }
        let used = all.len() - empty.len();
        out.push(d.help(format!(
            "connect activity, target rating and data of a behaviour to each channel, or set \
             <param name=\"channels\">{used}</param> if only {used} behaviour(s) are fused \
             (channels that are not fully connected stop the fusion)"
        )));
    }
}

/// Channel `k` of fusion `path` has some ports connected (`present`; `first` comes
/// first in the file) but not the `missing` ones: the finding, at `first`.
fn partly_connected(
    path: &str,
    k: u32,
    missing: &[&str],
    present: &[(Span, &str)],
    (at, first_name): (Span, &str),
) -> Diagnostic {
    let missing_list = list(missing);
    let mut d = Diagnostic::new(
        &CHECK,
        at,
        format!("fusion channel {k} of `{path}` has no {missing_list}"),
    )
    .label(format!(
        "channel {k}'s `{first_name}` is connected, but not its {missing_list}"
    ));
    for &(span, name) in present {
        if span != at {
            d = d.secondary(span, format!("channel {k}'s `{name}`"));
        }
    }
    d
}

/// The channels `empty` of fusion `path` (of `count` channels, counted at `count_at`)
/// have nothing connected.
fn unconnected(
    path: &str,
    empty: &[u32],
    count: usize,
    count_at: Span,
    declared: bool,
) -> Diagnostic {
    let which = empty
        .iter()
        .map(u32::to_string)
        .collect::<Vec<_>>()
        .join(", ");
    let (noun, verb) = if empty.len() == 1 {
        ("channel", "is")
    } else {
        ("channels", "are")
    };
    Diagnostic::new(
        &CHECK,
        count_at,
        format!("fusion `{path}`: {noun} {which} {verb} not connected at all"),
    )
    .label(if declared {
        format!("{count} channels declared here")
    } else {
        format!("{count} channels (the default)")
    })
}
