//! S108 `inline-step-may-block`: a `wait="inline"` container whose step could block
//! or run long, holding up the thread that delivers its data (a link's network
//! callback, another container).

use super::{duration, loads};
use crate::{CheckInfo, PassContext};
use ferroc_deadlock::render::Ctx;
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics, Severity};
use ferroc_diagnostics::source::Span;
use ferroc_model::ir::{Application, ElementId, ElementKind, Wait};

/// The longest declared budget (seconds, all modules of the container together) an
/// inline cycle may take: 1 ms holds up the delivering thread about as long as a
/// value of a few megabytes takes to cross the network on one computer.
pub const INLINE_BUDGET: f64 = 1e-3;

pub static CHECK: CheckInfo = CheckInfo {
    code: "S108",
    name: "inline-step-may-block",
    severity: Severity::Error,
    summary: "A `wait=\"inline\"` container's step could block or run long in the thread that delivers its data.",
    explanation: "A data-triggered container with `wait=\"inline\"` has no thread that waits for
data: its cycle runs in the thread that delivers the value (the network's receive
thread for a value from another part, the writer's container for one from this
part). That saves waking a sleeping thread, tens of microseconds on an idle CPU, but
while the cycle runs that thread does nothing else: every other value from the same
part, its keep-alives and the answers of service calls wait behind it. A step that
waits there for something only that thread would bring never ends.

So the container's cycle must be short and must never wait. This is an error where
the model shows that it can wait or take long:

- one of its modules calls a service (a call waits for the answer, which may come
  through the very thread the cycle holds), takes a lock, reads a queue waiting for
  an item, or writes into a queue with `on-full=\"block\"` (the deadlock model's
  wait-states of the container, with a timeout or without);
- a connection into one of its inputs has a queue with `on-full=\"block\"`: a writer
  delivering into it when it is full waits for a cycle to take a value, and that
  cycle can only run in a delivering thread (a link's writer waits in the network's
  receive thread: nothing from that part arrives any more);
- its modules' declared budgets add up to more than 1 ms;
- it is a pool (`pool=`), or it has `cpu=` or `priority=`: an inline container has no
  thread of its own to spread, pin or prioritise (it runs at the priority of
  whichever thread delivers).

A container whose outputs all drop when full (`on-full=\"drop-oldest\"`, the default,
or no queue) never waits to write and passes. `wait=` on a container that is not
data-triggered is M108.

Bad:
    <thread name=\"detect\" trigger=\"data\" wait=\"inline\">
      <module name=\"ask\" type=\"tm.Caller\"/>
    </thread>

Fix: keep `wait=\"park\"` (the default) for that container, or move the call, the lock
or the blocking write into another container that this one feeds through a queue
that drops.",
    fixtures: "compiler/checks/src/scheduling/s108_inline_step_may_block",
};

pub(crate) fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    let app = ctx.app;
    let inline: Vec<ElementId> = (app.elements.iter().enumerate())
        .filter(|(_, e)| {
            matches!(
                e.kind,
                ElementKind::Thread {
                    wait: Wait::Inline,
                    data_trigger: true,
                    ..
                }
            )
        })
        .map(|(i, _)| ElementId(i as u32))
        .collect();
    if inline.is_empty() {
        return;
    }
    let finding = |thread: ElementId, at: Span, what: String, label: String, help: &str| {
        Diagnostic::new(
            &CHECK,
            at,
            format!(
                "`{}` runs inline (wait=\"inline\"), but {what}",
                app.path(thread)
            ),
        )
        .label(label)
        .secondary(
            app.element(thread).name_span,
            "its cycle runs in the thread that delivers its data",
        )
        .help(help)
    };
    placement(app, &inline, out, &finding);
    let m = ctx.deadlock_model();
    let render = Ctx {
        app,
        libs: ctx.libraries,
        m,
    };
    let mut seen = hashbrown::HashSet::new();
    for (i, w) in m.waits.iter().enumerate() {
        let thread = m.ecs[w.ec as usize].thread;
        if !inline.contains(&thread) || !seen.insert((thread, w.site)) {
            continue;
        }
        out.push(finding(
            thread,
            w.site,
            format!("`{}` can wait in its step", app.path(w.module)),
            format!("waits here: {}", render.step(i as u32)),
            "keep wait=\"park\" for this container, or move what waits into a container it feeds through a queue that drops (on-full=\"drop-oldest\")",
        ));
    }
    for c in app.connections.iter().filter(|c| c.blocks_when_full()) {
        let Some(thread) = app.element(c.to.element()).thread else {
            continue;
        };
        if inline.contains(&thread) {
            out.push(finding(
                thread,
                c.to_span,
                "a writer into its input waits for room when the queue is full, and only a delivering thread runs its cycle".into(),
                "on-full=\"block\" into an inline container".into(),
                "let this queue drop (on-full=\"drop-oldest\"), or keep wait=\"park\" for the container",
            ));
        }
    }
    for load in loads(app, ctx.libraries, None) {
        let total = load.total();
        if !inline.contains(&load.thread) || total <= INLINE_BUDGET + super::EPS {
            continue;
        }
        let Some(biggest) = load.budgets.first() else {
            continue;
        };
        out.push(finding(
            load.thread,
            biggest.span,
            format!(
                "its modules' budgets add up to {}, over the {} an inline cycle may take",
                duration(total),
                duration(INLINE_BUDGET)
            ),
            format!(
                "`{}`: budget {}",
                app.path(biggest.module),
                duration(biggest.seconds)
            ),
            "keep wait=\"park\" for this container, or split the work: a short inline step that feeds a parked container through a queue that drops",
        ));
    }
}

/// `pool=`, `cpu=`, `priority=` on an inline container: there is no thread to place.
fn placement(
    app: &Application,
    inline: &[ElementId],
    out: &mut Diagnostics,
    finding: &impl Fn(ElementId, Span, String, String, &str) -> Diagnostic,
) {
    for &t in inline {
        if let ElementKind::Thread { pool: Some(n), .. } = app.element(t).kind {
            out.push(finding(
                t,
                app.element(t).name_span,
                format!("it is a pool of {n} workers"),
                "an inline container runs one cycle at a time, on the delivering thread".into(),
                "remove `pool`, or keep wait=\"park\" for this container",
            ));
        }
        for (attr, place) in [
            ("cpu", app.timing.cpu.get(&t)),
            ("priority", app.timing.priority.get(&t)),
        ] {
            if let Some((_, span)) = place {
                out.push(finding(
                    t,
                    *span,
                    format!("it has `{attr}=`, which would do nothing"),
                    "it has no thread of its own to place".into(),
                    &format!("remove `{attr}`, or keep wait=\"park\" for this container"),
                ));
            }
        }
    }
}
