//! B110 `characteristic-behaviours`: An iB2C group has more than one characteristic
//! behaviour.

use super::{characteristic_groups, list};
use crate::{CheckInfo, PassContext};
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics, Severity};
use ferroc_model::ir::ElementKind;

pub static CHECK: CheckInfo = CheckInfo {
    code: "B110",
    name: "characteristic-behaviours",
    severity: Severity::Error,
    summary: "An iB2C group has more than one characteristic behaviour.",
    explanation:
        "An iB2C group behaves like one behaviour to the outside: its stimulation, inhibition and
stimulation mode are those of its characteristic behaviour, and its activity and target
rating are that behaviour's outputs. A module says it is the characteristic behaviour of
its nearest enclosing group with `characteristic=\"true\"`. Two of them leave the group's
meta signals ambiguous. FINROC meant to throw \"This group already has a characteristic
module\" but constructs the exception without `throw`, so the second registration passes
silently and the group follows whichever came last.

Bad:
    <group name=\"explore\">
      <module name=\"wander\" type=\"nav.Wander\" characteristic=\"true\"/>
      <module name=\"follow_wall\" type=\"nav.FollowWall\" characteristic=\"true\"/>
    </group>

Fix: keep `characteristic=\"true\"` on the behaviour that stands for the group (often its
fusion), or split the group in two.",
    fixtures: "compiler/checks/src/behaviour/b110_characteristic_behaviours",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    let mut groups: Vec<_> = characteristic_groups(ctx.app).into_iter().collect();
    groups.sort_by_key(|(g, _)| *g);
    for (group, members) in groups {
        if members.len() < 2 {
            continue;
        }
        let span_of = |id| match &ctx.app.element(id).kind {
            ElementKind::Module(m) => m.characteristic(),
            _ => None,
        };
        let (Some(first), Some(second)) = (span_of(members[0]), span_of(members[1])) else {
            continue;
        };
        let names: Vec<&str> = members
            .iter()
            .map(|m| ctx.app.element(*m).name.as_str())
            .collect();
        let path = ctx.app.path(group);
        let mut d = Diagnostic::new(
            &CHECK,
            second,
            format!(
                "iB2C group `{path}` has {} characteristic behaviours: {}",
                members.len(),
                list(&names)
            ),
        )
        .label(format!(
            "`{}` is a second one",
            ctx.app.element(members[1]).name
        ))
        .secondary(
            first,
            format!(
                "`{}` is already characteristic",
                ctx.app.element(members[0]).name
            ),
        );
        for &m in &members[2..] {
            if let Some(span) = span_of(m) {
                d = d.secondary(span, "another one");
            }
        }
        d = d.secondary(ctx.app.element(group).name_span, "the group");
        out.push(d.help(
            "keep characteristic=\"true\" on the one behaviour whose activity and target rating \
             stand for the group (often its fusion), or split the group",
        ));
    }
}
