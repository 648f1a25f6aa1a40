//! B102 `meta-input-from-number`: A stimulation or inhibition input is fed by something
//! other than an activity.

use super::{behaviours, is_inhibition, meta_inputs, port_path, sources};
use crate::{CheckInfo, PassContext};
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics, Severity};
use ferroc_values::types::{compat, Compat, Meta, Type};

pub static CHECK: CheckInfo = CheckInfo {
    code: "B102",
    name: "meta-input-from-number",
    severity: Severity::Error,
    summary: "A stimulation or inhibition input is fed by something other than an activity.",
    explanation:
        "In iB2C, behaviours stimulate and inhibit each other with their activities: `a ≤ ι`
keeps every signal in [0, 1] and gives it a meaning (\"how much this behaviour wants to
act\"). A plain number — a speed, a distance, a count, even an `f64` that happens to lie in
[0, 1] today — has neither guarantee. FINROC declares this rule (\"Only activities may be
connected to stimulation or inhibition ports!\") but, through a C++ slip, never enforces
it; ferroc does. Accepted sources are activity outputs (a behaviour's `activity`, its
derived activities `activity/<name>`, or any module output of type `Activity`) and outputs
of the input's own meta type. Group ports are followed to the module that really sends.

Bad:
    <module name=\"battery\" type=\"nav.BatteryMonitor\"/>   <!-- out charge: f64 -->
    <connect from=\"battery/charge\" to=\"go_home/stimulation\"/>

Fix: convert explicitly, which also says how the number maps onto [0, 1]:
    <module name=\"low_charge\" type=\"ferroc_std.NumberToActivity\">
      <param name=\"min\">0.8</param><param name=\"max\">0.2</param>
    </module>
    <connect from=\"battery/charge\" to=\"low_charge/value\"/>
    <connect from=\"low_charge/activity\" to=\"go_home/stimulation\"/>",
    fixtures: "compiler/checks/src/behaviour/b102_meta_input_from_number",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for (id, _, _) in behaviours(ctx) {
        for (input, name) in meta_inputs(ctx, id) {
            let kind = match name {
                "stimulation" => Meta::Stimulation,
                n if is_inhibition(n) => Meta::Inhibition,
                _ => continue,
            };
            for s in sources(ctx.app, ctx.libraries, input) {
                let Some(view) = ctx.app.view(ctx.libraries, s.port) else {
                    continue;
                };
                let first = s.first(ctx.app);
                let ty = match (first.from_index, view.ty.element()) {
                    (Some(_), Some(e)) => e,
                    _ => view.ty,
                };
                let what = match ty {
                    Type::Meta(Meta::Activity) => continue,
                    Type::Meta(m) if *m == kind => continue,
                    Type::Meta(Meta::TargetRating) => {
                        "a target rating (the behaviour's discontent), not an activity".to_string()
                    }
                    Type::Meta(m) => format!("a `{m:?}`, not an activity"),
                    t if compat(t, &Type::Meta(kind)) == Compat::Incompatible => continue, // T102
                    t => format!("a plain `{t}`, not an activity"),
                };
                let target = format!("{}/{name}", ctx.app.path(id));
                let mut d = Diagnostic::new(
                    &CHECK,
                    first.from_span,
                    format!("`{target}` is fed by `{}`, {what}", port_path(ctx, s.port)),
                )
                .label(what.clone());
                if s.first != s.last {
                    d = d.secondary(s.last(ctx.app).to_span, format!("reaches `{name}` here"));
                } else {
                    d = d.secondary(first.to_span, format!("the {} input", name_of(kind)));
                }
                out.push(d.help(format!(
                    "only activities may {} a behaviour: put a `ferroc_std.NumberToActivity` \
                     between them (it maps [min, max] onto [0, 1]), or connect another \
                     behaviour's `activity` or derived activity",
                    if kind == Meta::Stimulation {
                        "stimulate"
                    } else {
                        "inhibit"
                    }
                )));
            }
        }
    }
}

fn name_of(kind: Meta) -> &'static str {
    match kind {
        Meta::Stimulation => "stimulation",
        _ => "inhibition",
    }
}
