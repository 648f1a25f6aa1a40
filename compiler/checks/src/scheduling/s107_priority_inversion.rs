//! S107 `priority-inversion`: a higher-priority thread container can wait, without a
//! timeout, for a lower-priority one that shares its core.

use crate::{CheckInfo, PassContext};
use ferroc_deadlock::{Held, Model, WaitKind};
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics, Severity};
use ferroc_diagnostics::source::Span;
use ferroc_model::ir::{Application, ElementId};

pub static CHECK: CheckInfo = CheckInfo {
    code: "S107",
    name: "priority-inversion",
    severity: Severity::Warning,
    summary: "A higher-priority thread container can block on a lower-priority one on the same core.",
    explanation:
        "A thread container with a higher `priority` that waits without a timeout for a
lower-priority one — a lock the other takes, or a synchronous call into a service the
other executes — is held up for as long as the lower one needs, and any medium-priority
thread that preempts the lower one delays the higher one too (unbounded priority
inversion; Sha, Rajkumar, Lehoczky 1990). This is reported when both priorities are
declared and the two containers can share a core: same host, and not pinned to
different cores (`cpu=`). Equal priorities, waits with a timeout and asynchronous calls
are not reported.

Bad:
    <part name=\"robot\" host=\"pc\">
      <thread name=\"control\" period=\"1ms\" priority=\"90\"><module name=\"arm\" type=\"dl.LockAB\"/></thread>
      <thread name=\"logger\" period=\"100ms\" priority=\"10\"><module name=\"log\" type=\"dl.LockAB\"/></thread>
    </part>

Fix: do not share the lock (or the service) between the two, give the lower container
the higher priority while it serves (raise its priority), pin them to different cores,
or give the wait a timeout.",
    fixtures: "compiler/checks/src/scheduling/s107_priority_inversion",
};

/// One hard wait edge between two containers.
struct Edge {
    high: ElementId,
    low: ElementId,
    site: Span,
    what: String,
}

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    let app = ctx.app;
    if app.timing.priority.len() < 2 {
        return;
    }
    let edges = blocking_edges(ctx, ctx.deadlock_model());
    let mut seen = hashbrown::HashSet::new();
    for e in edges {
        if e.high == e.low || !seen.insert((e.high, e.low)) {
            continue;
        }
        let (Some(&(ph, hs)), Some(&(pl, ls))) = (
            app.timing.priority.get(&e.high),
            app.timing.priority.get(&e.low),
        ) else {
            continue;
        };
        if ph <= pl || !share_core(app, e.high, e.low) {
            continue;
        }
        out.push(
            Diagnostic::new(
                &CHECK,
                e.site,
                format!(
                    "priority inversion: `{}` (priority {ph}) can wait without a timeout for `{}` (priority {pl}), which shares its core",
                    app.path(e.high),
                    app.path(e.low)
                ),
            )
            .label(format!("`{}` waits here for {}", app.path(e.high), e.what))
            .secondary(hs, format!("`{}`: priority {ph}", app.path(e.high)))
            .secondary(ls, format!("`{}`: priority {pl}", app.path(e.low)))
            .help(format!(
                "do not share this between the two containers, raise `{}` to priority {ph} or more, pin the two to different cores (cpu=), or give the wait a timeout",
                app.path(e.low)
            )),
        );
    }
}

/// The contexts that take each lock (sorted, once each).
fn lock_takers(m: &Model) -> Vec<Vec<u32>> {
    let mut takers: Vec<Vec<u32>> = vec![Vec::new(); m.locks.len()];
    for w in &m.waits {
        if let WaitKind::Lock { lock } = w.kind {
            takers[lock as usize].push(w.ec);
        }
        for h in &w.held {
            if let Held::Lock(l) = h {
                takers[*l as usize].push(w.ec);
            }
        }
    }
    for t in &mut takers {
        t.sort_unstable();
        t.dedup();
    }
    takers
}

/// Waits without a timeout of one thread container for another: for a lock another
/// takes, or for the reply of a service another runs.
fn blocking_edges(ctx: &PassContext<'_>, m: &Model) -> Vec<Edge> {
    let app = ctx.app;
    let thread = |ec: u32| m.ecs[ec as usize].thread;
    let takers = lock_takers(m);
    let mut edges: Vec<Edge> = Vec::new();
    for w in m.waits.iter().filter(|w| w.timeout.is_none()) {
        match &w.kind {
            WaitKind::Lock { lock } => {
                for &y in &takers[*lock as usize] {
                    edges.push(Edge {
                        high: thread(w.ec),
                        low: thread(y),
                        site: w.site,
                        what: format!(
                            "lock `{}`, which `{}` also takes",
                            m.locks[*lock as usize].name,
                            app.path(thread(y))
                        ),
                    });
                }
            }
            WaitKind::Call {
                client, targets, ..
            } => {
                for t in targets.iter().filter(|t| !t.inline) {
                    let Some(y) = t.ec else { continue };
                    let service = app
                        .module_type(ctx.libraries, t.module)
                        .map_or("?", |mt| mt.services[t.service].name.as_str());
                    edges.push(Edge {
                        high: thread(w.ec),
                        low: thread(y),
                        site: w.site,
                        what: format!(
                            "the reply to sync call `{client}`: service `{}`.{service} runs there",
                            app.path(t.module)
                        ),
                    });
                }
            }
            _ => {}
        }
    }
    edges
}

/// Same host, and not pinned to different cores.
fn share_core(app: &Application, a: ElementId, b: ElementId) -> bool {
    let host = |t: ElementId| app.element(t).part.map(|p| app.host_of(p));
    if host(a) != host(b) {
        return false;
    }
    match (app.timing.cpu.get(&a), app.timing.cpu.get(&b)) {
        (Some(x), Some(y)) => x.0 == y.0,
        _ => true,
    }
}
