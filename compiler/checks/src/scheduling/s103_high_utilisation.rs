//! S103 `high-utilisation`: a periodic thread container is loaded above the warning
//! threshold, counting the timeouts of its blocking steps.

use super::{duration, loads, percent, Load, EPS};
use crate::{CheckInfo, PassContext};
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics, Severity};

/// The threshold when the application declares none (`utilisation-warning`).
pub const DEFAULT_THRESHOLD: f64 = 0.8;

pub static CHECK: CheckInfo = CheckInfo {
    code: "S103",
    name: "high-utilisation",
    severity: Severity::Warning,
    summary: "A periodic thread container's worst-case response time is above the warning threshold of its period.",
    explanation:
        "The worst-case response time of a periodic thread container is the sum of its
modules' budgets plus the timeout of every blocking step with a timeout (a call or a
read that may wait that long: `reference/deadlocks.md` §1(f)). Above a threshold of the
period (80 % unless `<application utilisation-warning=\"90%\">` says otherwise) there is
little margin for jitter, and when the timeouts alone push the cycle past its period, a
timeout that fires overruns it. Budgets alone above 100 % are S102 instead.

Bad (utilisation-warning 80 %):
    <thread name=\"control\" period=\"10ms\">
      <module name=\"planner\" type=\"nav.Planner\" budget=\"6ms\"/>
      <module name=\"mapper\" type=\"nav.Mapper\" budget=\"3ms\"/>
    </thread>

Fix: lengthen the period, move modules to another container, shorten the timeouts, or
raise the threshold if the margin is known to be enough.",
    fixtures: "compiler/checks/src/scheduling/s103_high_utilisation",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    let threshold = ctx.app.timing.warning.map_or(DEFAULT_THRESHOLD, |w| w.0);
    for load in loads(ctx.app, ctx.libraries, Some(ctx.deadlock_model())) {
        let Some(period) = load.period else { continue };
        if load.total() > period * (1.0 + EPS) {
            continue; // S102
        }
        let response = load.total() + load.timeout_total();
        if response > threshold * period * (1.0 + EPS) {
            out.push(report(ctx, &load, period, threshold));
        }
    }
}

fn report(ctx: &PassContext<'_>, load: &Load, period: f64, threshold: f64) -> Diagnostic {
    let app = ctx.app;
    let thread = app.element(load.thread);
    let response = load.total() + load.timeout_total();
    let timeouts = load.timeout_total();
    let head = if timeouts > 0.0 {
        format!(
            "thread container `{}` may need {} of its {} period ({}): budgets {} plus timeouts {}",
            app.path(load.thread),
            duration(response),
            duration(period),
            percent(response / period),
            duration(load.total()),
            duration(timeouts)
        )
    } else {
        format!(
            "thread container `{}` is loaded to {} of its {} period ({} of budgets)",
            app.path(load.thread),
            percent(response / period),
            duration(period),
            duration(load.total())
        )
    };
    let over = if response > period * (1.0 + EPS) {
        "a timeout that fires overruns the period".to_string()
    } else {
        format!("above the warning threshold of {}", percent(threshold))
    };
    let over = over + &super::s102_period_overrun::unbudgeted(load);
    let mut d = Diagnostic::new(&CHECK, thread.name_span, head).label(over);
    d = super::s102_period_overrun::contributors(ctx, d, load);
    for (t, site) in load.timeouts.iter().take(3) {
        d = d.secondary(
            *site,
            format!("a blocking step here may wait {}", duration(*t)),
        );
    }
    let mut help = String::from(
        "lengthen the period, move modules into another thread container, or make them cheaper",
    );
    if timeouts > 0.0 {
        help.push_str("; shorten the timeouts");
    }
    if app.timing.warning.is_some() {
        help.push_str("; or raise utilisation-warning if this margin is enough");
    } else {
        help.push_str(
            "; or set <application utilisation-warning=\"90%\"> if this margin is enough",
        );
    }
    d.help(help)
}
