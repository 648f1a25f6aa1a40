//! F105 `group-output-unwritten`: an output port of a group that nothing inside writes.

use ferroc_diagnostics::check::CheckInfo;
use ferroc_diagnostics::diagnostic::Severity;

pub static CHECK: CheckInfo = CheckInfo {
    code: "F105",
    name: "group-output-unwritten",
    severity: Severity::Warning,
    summary: "A group declares an output port that nothing inside the group writes.",
    explanation: "A port of a group's output interface (`Output`, `Sensor Output`, `Controller
Output`) is a proxy: it only forwards what an inner port publishes. When no edge of the
group (in its file, or made by its C++ constructor as the catalogue records) leads into
it, whoever connects to it outside receives nothing but the default value, without any
warning from FINROC.

Bad:
    <interface name=\"Output\"><port name=\"Speed\" type=\"double\"/></interface>
    (and no <edge ... dest=\"Output/Speed\"/>)

Fix: connect an inner output to the port, or remove the port.",
    fixtures: "compiler/finroc/src/checks/f105_group_output_unwritten",
};

use super::{Context, Facts};
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics};

fn is_output_interface(name: &str) -> bool {
    matches!(name, "Output" | "Sensor Output" | "Controller Output")
}

pub fn check(ctx: &Context<'_>, facts: &Facts<'_>, out: &mut Diagnostics) {
    let constructor_edges = facts
        .scope
        .owner
        .and_then(|o| o.content.as_ref())
        .map(|c| c.edges.as_slice())
        .unwrap_or_default();
    let written = |interface: &str, port: &str| {
        ctx.doc.edges.iter().chain(constructor_edges).any(|e| {
            // Written: the port is the destination, or the source of an edge that FINROC
            // re-orients (its other end is an inner output).
            let is = |end: &crate::finstructable::EdgeEnd| {
                end.scheme.is_none() && !end.absolute && end.segments == [interface, port]
            };
            let inner_output = |end: &crate::finstructable::EdgeEnd| {
                end.segments.len() > 2 && end.segments[end.segments.len() - 2].ends_with("Output")
            };
            is(&e.dest) || (is(&e.src) && inner_output(&e.dest))
        })
    };
    for interface in &ctx.doc.interfaces {
        if !is_output_interface(&interface.name.text) {
            continue;
        }
        for port in &interface.ports {
            if !written(&interface.name.text, &port.name.text) {
                out.push(
                    Diagnostic::new(
                        &CHECK,
                        port.name.span,
                        format!("nothing inside the group writes `{}/{}`", interface.name.text, port.name.text),
                    )
                    .label("this output only ever carries its default value")
                    .help(format!(
                        "add an <edge src=\"Element/Output/…\" dest=\"{}/{}\"/>, or remove the port",
                        interface.name.text, port.name.text
                    )),
                );
            }
        }
    }
    // The group type's own outputs (C++ members, catalogue), in the group's file.
    let Some(owner) = facts
        .scope
        .owner
        .filter(|o| o.composite && o.xml_file.is_some())
    else {
        return;
    };
    let unwritten: Vec<String> = owner
        .ports
        .iter()
        .filter(|p| is_output_interface(&p.interface) && !written(&p.interface, &p.name))
        .map(|p| format!("`{}/{}`", p.interface, p.name))
        .collect();
    if !unwritten.is_empty() {
        out.push(
            Diagnostic::new(
                &CHECK,
                ctx.doc.root_span,
                format!(
                    "nothing in group `{}` writes its output(s) {}",
                    owner.name,
                    unwritten.join(", ")
                ),
            )
            .label(format!("the group file of `{}` (its C++ constructor writes none of them either)", owner.name))
            .help("connect an inner output to each, e.g. <edge src=\"Element/Controller Output/…\" dest=\"Controller Output/…\"/>"),
        );
    }
}
