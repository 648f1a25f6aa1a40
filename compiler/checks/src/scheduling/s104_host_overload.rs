//! S104 `host-overload`: the thread containers on one host need more cores than it has.

use super::{duration, loads, percent, EPS};
use crate::{CheckInfo, PassContext};
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics, Severity};
use ferroc_diagnostics::source::Span;
use ferroc_model::ir::{ElementId, ElementKind, HostKey, Wait};

pub static CHECK: CheckInfo = CheckInfo {
    code: "S104",
    name: "host-overload",
    severity: Severity::Error,
    summary: "The thread containers on one host need more cores than the host has.",
    explanation:
        "Each periodic thread container with budgets uses a share of one core: its budgets
divided by its period. A data-triggered container with `wait=\"spin\"` busy-polls for
data and uses a whole core, whatever its budgets. All parts with the same `host` label run on one machine; when the
shares of all their containers add up to more than the machine's cores
(`<part cores=\"n\">`), no scheduler can run them all in time, whatever the priorities.
Hosts without a declared core count are not checked. Parts without a `host` label are a
host of their own. When parts of one host declare different core counts, the smallest
is used.

Bad:
    <part name=\"robot\" host=\"pi\" cores=\"1\">
      <thread name=\"a\" period=\"10ms\"><module name=\"x\" type=\"nav.Planner\" budget=\"7ms\"/></thread>
      <thread name=\"b\" period=\"10ms\"><module name=\"y\" type=\"nav.Mapper\" budget=\"6ms\"/></thread>
    </part>

Fix: move containers to another host, lengthen their periods, make modules cheaper, or
declare the real core count.",
    fixtures: "compiler/checks/src/scheduling/s104_host_overload",
};

struct Host {
    /// Smallest declared core count, with the part that declares it.
    cores: Option<(u32, Span)>,
    /// (thread, utilisation)
    containers: Vec<(ElementId, f64)>,
    label: String,
}

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    let app = ctx.app;
    if app.timing.cores.is_empty() {
        return;
    }
    let mut hosts: Vec<Host> = Vec::new();
    let mut index: hashbrown::HashMap<HostKey<'_>, usize> = hashbrown::HashMap::new();
    let mut host = |part: ElementId, hosts: &mut Vec<Host>| -> usize {
        let key = app.host_of(part);
        *index.entry(key).or_insert_with(|| {
            hosts.push(Host {
                cores: None,
                containers: Vec::new(),
                label: match key {
                    HostKey::Label(l) => format!("host `{l}`"),
                    HostKey::Part(p) => format!("part `{}` (no host label)", app.path(p)),
                },
            });
            hosts.len() - 1
        })
    };
    let mut parts: Vec<(&ElementId, &(u32, Span))> = app.timing.cores.iter().collect();
    parts.sort();
    for (part, cores) in parts {
        let h = host(*part, &mut hosts);
        if hosts[h].cores.is_none_or(|c| cores.0 < c.0) {
            hosts[h].cores = Some(*cores);
        }
    }
    for load in loads(app, ctx.libraries, None) {
        let (Some(u), Some(part)) = (load.utilisation(), app.element(load.thread).part) else {
            continue;
        };
        let h = host(part, &mut hosts);
        hosts[h].containers.push((load.thread, u));
    }
    // A spinning container never leaves its core (data-triggered: not among the loads
    // above, which only count periodic containers).
    for (i, e) in app.elements.iter().enumerate() {
        if let (
            ElementKind::Thread {
                data_trigger: true,
                wait: Wait::Spin,
                pool: None,
                ..
            },
            Some(part),
        ) = (&e.kind, e.part)
        {
            let h = host(part, &mut hosts);
            hosts[h].containers.push((ElementId(i as u32), 1.0));
        }
    }
    for h in &hosts {
        let Some((cores, span)) = h.cores else {
            continue;
        };
        let total: f64 = h.containers.iter().map(|c| c.1).sum();
        if total > cores as f64 * (1.0 + EPS) {
            out.push(report(ctx, h, cores, span, total));
        }
    }
}

fn report(ctx: &PassContext<'_>, h: &Host, cores: u32, span: Span, total: f64) -> Diagnostic {
    let app = ctx.app;
    let mut containers = h.containers.clone();
    containers.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    let cores_text = if cores == 1 {
        "1 core".to_string()
    } else {
        format!("{cores} cores")
    };
    let mut d = Diagnostic::new(
        &CHECK,
        span,
        format!(
            "{} is overloaded: its thread containers need {:.2} cores' worth of time ({}), but it has {cores_text}",
            h.label,
            total,
            percent(total)
        ),
    )
    .label(format!("{cores_text} declared here"));
    for (thread, u) in &containers {
        let why = match app.element(*thread).kind {
            ElementKind::Thread {
                period: Some(p), ..
            } => format!("period {}", duration(p)),
            ElementKind::Thread {
                wait: Wait::Spin, ..
            } => "it spins while waiting for data: wait=\"spin\"".into(),
            _ => "?".into(),
        };
        d = d.secondary(
            app.element(*thread).name_span,
            format!(
                "`{}` uses {} of a core ({why})",
                app.path(*thread),
                percent(*u)
            ),
        );
    }
    d.help(format!(
        "move thread containers (the busiest is `{}`) to another host, lengthen their periods, make their modules cheaper or let spinning containers wait=\"adaptive\"; or declare the real number of cores",
        app.path(containers[0].0)
    ))
}
