//! B104 `stimulation-ignored`: A behaviour in stimulation mode `enabled` or `disabled`
//! has a connected stimulation, which it ignores.

use super::{behaviours, stimulation_mode, Mode};
use crate::{CheckInfo, PassContext};
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics, Severity};
use ferroc_model::ir::Endpoint;

pub static CHECK: CheckInfo = CheckInfo {
    code: "B104",
    name: "stimulation-ignored",
    severity: Severity::Warning,
    summary:
        "A behaviour in stimulation mode `enabled`/`disabled` ignores its connected stimulation.",
    explanation:
        "Stimulation mode `enabled` fixes a behaviour's stimulation at 1, `disabled` at 0; whatever
arrives at its `stimulation` input is ignored. A connection into it is then either dead
wiring or a sign that the mode was set by mistake (FINROC warns at run time: \"… but
stimulation port also connected. Ignoring incoming value.\").

Bad:
    <module name=\"avoid\" type=\"nav.AvoidObstacles\">
      <param name=\"stimulation_mode\">enabled</param>
    </module>
    <connect from=\"explore/activity\" to=\"avoid/stimulation\"/>

Fix: remove the connection, or remove the `stimulation_mode` parameter (`auto`, the
default, follows the input).",
    fixtures: "compiler/checks/src/behaviour/b104_stimulation_ignored",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for (id, m, mt) in behaviours(ctx) {
        let Some((mode @ (Mode::Enabled | Mode::Disabled), Some(span))) = stimulation_mode(m)
        else {
            continue;
        };
        let Some(&port) = mt.port_index.get("stimulation") else {
            continue;
        };
        let input = Endpoint::Port {
            element: id,
            port: port as u32,
        };
        let mut incoming: Vec<_> = ctx.app.incoming(input).collect();
        if incoming.is_empty() {
            continue;
        }
        incoming.sort_by_key(|c| (c.to_span.file, c.to_span.start));
        let (word, value) = if mode == Mode::Enabled {
            ("enabled", 1)
        } else {
            ("disabled", 0)
        };
        let path = ctx.app.path(id);
        let mut d = Diagnostic::new(
            &CHECK,
            span,
            format!(
                "behaviour `{path}` is `{word}`: the connection into its stimulation is ignored"
            ),
        )
        .label(format!("`{word}` fixes the stimulation at {value}"));
        for c in &incoming {
            d = d.secondary(c.to_span, "ignored connection");
        }
        out.push(d.help(format!(
            "remove the connection into `{path}/stimulation`, or remove the \
             `stimulation_mode` parameter so that the behaviour follows its stimulation (`auto`)"
        )));
    }
}
