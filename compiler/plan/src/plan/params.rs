//! Connections into module parameters (`<connect to="…/param">`), planned after the
//! data connections: a parameter link between parts is numbered after the data links.

use super::{links, unit_scale, Plan, PlannedParamLink, Unsupported};
use ferroc_model::ir::{Application, Endpoint};
use ferroc_model::library::LibrarySet;

/// Connections into module parameters. Only a module output straight into a module's
/// parameter is realised; through group ports it is refused by name (not ignored).
pub(super) fn plan_param_links(
    app: &Application,
    libs: &LibrarySet,
    paths: &[String],
    plan: &mut Plan,
    problems: &mut Vec<Unsupported>,
) {
    for (hop, c) in app.connections.iter().enumerate() {
        let Endpoint::Param {
            element: target, ..
        } = c.to
        else {
            continue;
        };
        let (Some(from), Some(to)) = (app.view(libs, c.from), app.view(libs, c.to)) else {
            continue;
        };
        let Endpoint::Port {
            element: source, ..
        } = c.from
        else {
            problems.push(Unsupported {
                what:
                    "a parameter driven through a group port is not supported by the runtime yet; \
                       connect the module output to the parameter directly"
                        .into(),
                span: c.span,
            });
            continue;
        };
        let scale = unit_scale(from.unit, to.unit);
        let id = (plan.connections.iter().filter(|c| c.link.is_some()).count()
            + plan.param_links.iter().filter(|l| l.link.is_some()).count()) as u32;
        plan.param_links.push(PlannedParamLink {
            from: (paths[source.0 as usize].clone(), from.name.to_string()),
            to: (paths[target.0 as usize].clone(), to.name.to_string()),
            scale,
            link: links::param_link_of(app, hop, (source, target), id),
            span: c.span,
        });
    }
}
