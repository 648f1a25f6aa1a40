//! S102 `period-overrun`: the budgets of a periodic thread container exceed its period.

use super::{duration, loads, percent, Load, EPS};
use crate::{CheckInfo, PassContext};
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics, Severity};

pub static CHECK: CheckInfo = CheckInfo {
    code: "S102",
    name: "period-overrun",
    severity: Severity::Error,
    summary: "The budgets of a periodic thread container add up to more than its period.",
    explanation: "A periodic thread container runs all its modules one after the other in every
cycle. When the worst-case execution budgets (`budget=` on the module type or on the
instance) add up to more than the period, the container overruns whenever the modules
take what they declared: the next cycle starts late, and everything downstream sees old
data. Exactly 100 % is not reported (but S103 warns above the threshold). A module's
budget covers everything it does in one cycle (both steps of a sense-control module);
modules without a budget count as 0.

Bad:
    <thread name=\"control\" period=\"10ms\">
      <module name=\"planner\" type=\"nav.Planner\" budget=\"8ms\"/>
      <module name=\"mapper\" type=\"nav.Mapper\" budget=\"4ms\"/>
    </thread>

Fix: give the container a longer period, move modules into another thread container,
or make the largest contributors cheaper (and lower their declared budgets).",
    fixtures: "compiler/checks/src/scheduling/s102_period_overrun",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    for load in loads(ctx.app, ctx.libraries, None) {
        let Some(period) = load.period else { continue };
        if load.total() > period * (1.0 + EPS) {
            out.push(report(ctx, &load, period));
        }
    }
}

fn report(ctx: &PassContext<'_>, load: &Load, period: f64) -> Diagnostic {
    let app = ctx.app;
    let thread = app.element(load.thread);
    let mut d = Diagnostic::new(
        &CHECK,
        thread.name_span,
        format!(
            "thread container `{}` overruns its period: its modules' budgets add up to {} in a period of {} ({})",
            app.path(load.thread),
            duration(load.total()),
            duration(period),
            percent(load.total() / period)
        ),
    )
    .label(format!(
        "needs {} every {}{}",
        duration(load.total()),
        duration(period),
        unbudgeted(load)
    ));
    d = contributors(ctx, d, load);
    let biggest = &load.budgets[0];
    d.help(format!(
        "lengthen the period to at least {}, move modules (the largest is `{}`) into another thread container, or make them cheaper",
        duration(load.total()),
        app.path(biggest.module)
    ))
}

/// Secondary labels on the largest contributors (at most three), and the count of the
/// rest in the last label.
pub(super) fn contributors(ctx: &PassContext<'_>, mut d: Diagnostic, load: &Load) -> Diagnostic {
    let total = load.total();
    for b in load.budgets.iter().take(3) {
        let source = if b.from_type {
            ctx.app
                .module_type(ctx.libraries, b.module)
                .map_or(String::new(), |mt| format!(", budget of {}", mt.qualified))
        } else {
            String::new()
        };
        d = d.secondary(
            b.span,
            format!(
                "`{}`: {} ({} of the total{source})",
                ctx.app.path(b.module),
                duration(b.seconds),
                percent(b.seconds / total)
            ),
        );
    }

    d
}

/// `; 2 modules without a budget count as 0` when there are such modules.
pub(super) fn unbudgeted(load: &Load) -> String {
    match load.unbudgeted {
        0 => String::new(),
        1 => "; 1 module without a budget counts as 0".into(),
        n => format!("; {n} modules without a budget count as 0"),
    }
}
