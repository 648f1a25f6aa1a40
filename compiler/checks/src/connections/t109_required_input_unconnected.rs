//! T109 `required-input-unconnected`: An input declared `required="true"` has no connection.

use crate::CheckInfo;
use crate::PassContext;
use ferroc_diagnostics::diagnostic::Severity;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};
use ferroc_diagnostics::source::Span;
use ferroc_model::ir::{Application, ElementId, Endpoint};
use ferroc_model::library::PortDir;

pub static CHECK: CheckInfo = CheckInfo {
    code: "T109",
    name: "required-input-unconnected",
    severity: Severity::Error,
    summary: "An input declared `required=\"true\"` has no connection, or only through group ports nothing feeds.",
    explanation: "A module type declares `required=\"true\"` on inputs it cannot work without. Such a module
would wait or compute garbage forever.

Bad:
    <module name=\"loc\" type=\"nav.Localizer\"/>   <!-- its required input `scan` is never connected -->

A connection to a group port that nothing feeds is no source either: the input is
reached only through group ports, and no module output is at their other end.

Bad:
    <group name=\"nav\">
      <port name=\"scan\" dir=\"in\" type=\"nav.Scan\"/>   <!-- nothing feeds nav/scan -->
      <module name=\"loc\" type=\"nav.Localizer\"/>
      <connect from=\"scan\" to=\"loc/scan\"/>
    </group>

Fix: connect the input, or the group port that leads to it.",
    fixtures: "compiler/checks/src/connections/t109_required_input_unconnected",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for (id, m) in ctx.app.modules() {
        for (k, port) in ctx.app.module_ports(ctx.libraries, id) {
            if !port.required || port.dir != PortDir::In {
                continue;
            }
            let ep = Endpoint::Port {
                element: id,
                port: k,
            };
            if ctx.app.cut_off.contains(&ep) || ctx.app.ros2.binds(ep) {
                continue;
            }
            let connected = ctx.app.node(ep).is_some() && ctx.app.incoming(ep).next().is_some();
            if connected {
                // Connected: through group ports, some module output must be at the end.
                if crate::behaviour::sources(ctx.app, ctx.libraries, ep).is_empty() {
                    out.push(unfed(ctx, id, &port.name, port.span, ep));
                }
                continue;
            }
            let element = ctx.app.element(id);
            let mut d = Diagnostic::new(
                &CHECK,
                element.name_span,
                format!(
                    "required input `{}` of `{}` is not connected",
                    port.name,
                    ctx.app.path(id)
                ),
            )
            .label(format!("`{}` needs `{}`", element.name, port.name))
            .secondary(port.span, "declared required here");
            if let Some(at) = element.instantiated_at {
                d = d.secondary(at, "in this instance");
            }
            let _ = m;
            out.push(d.help(format!(
                "add <connect from=\"…\" to=\"{}/{}\"/>",
                element.name, port.name
            )));
        }
    }
}

/// The required input `ep` of module `id` is connected only to group ports no module
/// output reaches: named with the group port where the route ends.
fn unfed(
    ctx: &PassContext<'_>,
    id: ElementId,
    port: &str,
    declared: Span,
    ep: Endpoint,
) -> Diagnostic {
    let element = ctx.app.element(id);
    let mut d = Diagnostic::new(
        &CHECK,
        element.name_span,
        format!(
            "required input `{port}` of `{}` is connected only through group ports nothing feeds",
            ctx.app.path(id)
        ),
    )
    .label(format!("`{}` needs `{port}`", element.name))
    .secondary(declared, "declared required here");
    let ends = dead_ends(ctx.app, ep);
    for &(group, index) in &ends {
        let gp = &ctx.app.element(group).group_ports[index as usize];
        d = d.secondary(
            gp.span,
            format!("nothing feeds `{}/{}`", ctx.app.path(group), gp.name),
        );
    }
    let help = match ends.first() {
        Some(&(group, index)) => {
            let gp = &ctx.app.element(group).group_ports[index as usize];
            format!(
                "connect a module output to the group port `{}/{}` (in the group's parent: <connect from=\"…\" to=\"{}/{}\"/>)",
                ctx.app.path(group),
                gp.name,
                ctx.app.element(group).name,
                gp.name
            )
        }
        None => format!("connect a module output to `{port}`"),
    };
    d.help(help)
}

/// The group ports on the way back from `input` that nothing is connected to, in the
/// order they are found (each once).
fn dead_ends(app: &Application, input: Endpoint) -> Vec<(ElementId, u32)> {
    let mut ends = Vec::new();
    let mut seen = hashbrown::HashSet::new();
    let mut stack = vec![input];
    while let Some(ep) = stack.pop() {
        let mut fed = false;
        for c in app.incoming(ep) {
            fed = true;
            let from = c.from;
            if matches!(from, Endpoint::GroupPort { .. }) && seen.insert(from) {
                stack.push(from);
            }
        }
        if let (false, Endpoint::GroupPort { element, port }) = (fed, ep) {
            ends.push((element, port));
        }
    }
    ends
}
