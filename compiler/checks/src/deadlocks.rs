//! Checks of area deadlocks (D): `reference/deadlocks.md` via [`ferroc_deadlock`].
//!
//! The analysis runs once, in the pass registered for D101, and its findings are reported
//! under the code of the check each belongs to. Every D check's file holds its identity,
//! explanation and fixtures; D104, D109, D111 and D115–D117 also hold the wording of
//! their findings, which this pass calls.

use crate::PassContext;
use ferroc_deadlock::render::{seconds, Ctx};
use ferroc_deadlock::{self as deadlock, Cycle, CycleKind, StepFindingKind, WaitKind};
use ferroc_diagnostics::diagnostic::{Diagnostic, Diagnostics, Severity};

pub mod d101_call_cycle;
pub mod d102_response_context;
pub mod d103_lock_order_inversion;
pub mod d104_recursive_lock;
pub mod d105_mixed_wait_cycle;
pub mod d106_empty_queue_ring;
pub mod d107_full_queue_ring;
pub mod d108_pool_exhaustion;
pub mod d109_wait_never_served;
pub mod d110_same_thread_queue_read;
pub mod d111_unconnected_call;
pub mod d112_deadlock_unverified;
pub mod d113_call_always_times_out;
pub mod d114_timeout_race;
pub mod d115_trigger_cycle_never_runs;
pub mod d116_lock_level_violation;
pub mod d117_latent_lock_inversion;

/// The pass behind every D check.
pub fn run(ctx: &PassContext<'_>, out: &mut Diagnostics) {
    let m = ctx.deadlock_model();
    let a = deadlock::analyse(ctx.app, ctx.libraries, m);
    let cx = Ctx {
        app: ctx.app,
        libs: ctx.libraries,
        m,
    };
    for c in &a.cycles {
        out.push(cycle(&cx, c));
    }
    for h in &a.hangs {
        out.push(d109_wait_never_served::report(&cx, h.wait));
    }
    for f in &m.step_findings {
        out.push(match &f.kind {
            StepFindingKind::Recursive { lock, first } => {
                d104_recursive_lock::report(&cx, f, *lock, *first)
            }
            StepFindingKind::Level {
                lock,
                outer,
                outer_site,
            } => d116_lock_level_violation::report(&cx, f, *lock, *outer, *outer_site),
            StepFindingKind::Unconnected { client } => {
                d111_unconnected_call::report(&cx, f, client)
            }
        });
    }
    for d in &a.dead_triggers {
        out.push(d115_trigger_cycle_never_runs::report(&cx, d));
    }
    for l in &a.latent {
        out.push(d117_latent_lock_inversion::report(&cx, l));
    }
}

/// One witness cycle, under the code of its kind.
fn cycle(cx: &Ctx<'_>, c: &Cycle) -> Diagnostic {
    let ring = cx.ring(c);
    let n = {
        let mut ecs: Vec<u32> = c
            .steps
            .iter()
            .map(|(w, _)| cx.m.waits[*w as usize].ec)
            .collect();
        ecs.sort_unstable();
        ecs.dedup();
        ecs.len()
    };
    let threads = if n == 1 {
        "1 thread".to_string()
    } else {
        format!("{n} threads")
    };
    if c.unverified {
        return cx.diagnostic(
            &d112_deadlock_unverified::CHECK,
            c,
            format!("possible deadlock (consistency not established): {} wait-states of {threads} can wait for each other: {ring}", c.steps.len()),
        );
    }
    if c.soft {
        return timed_cycle(cx, c, &threads, &ring);
    }
    hard_cycle(cx, c, &threads, &ring)
}

/// A cycle that only a timeout breaks: a call that always times out (D113) or a
/// possible stall (D114).
fn timed_cycle(cx: &Ctx<'_>, c: &Cycle, threads: &str, ring: &str) -> Diagnostic {
    let first = &cx.m.waits[c.steps[0].0 as usize];
    let timeout = c
        .steps
        .iter()
        .filter_map(|(w, _)| cx.m.waits[*w as usize].timeout)
        .fold(0.0, f64::max);
    if c.certain {
        return cx.diagnostic(
            &d113_call_always_times_out::CHECK,
            c,
            format!(
                "this call always times out after {}: the request chain needs {}, which is blocked in the call ({ring})",
                seconds(timeout),
                cx.thread(first.ec)
            ),
        );
    }
    let overruns = c.steps.iter().any(|(w, _)| {
        cx.m.ecs[cx.m.waits[*w as usize].ec as usize]
            .period
            .is_some_and(|p| timeout >= p)
    });
    let d = cx.diagnostic(
        &d114_timeout_race::CHECK,
        c,
        format!("{threads} can wait for each other ({ring}); only a timeout of {} breaks it: a possible stall", seconds(timeout)),
    );
    if overruns {
        d.severity(Severity::Warning)
    } else {
        d
    }
}

/// A cycle nothing breaks: a deadlock, under the code of its kind.
fn hard_cycle(cx: &Ctx<'_>, c: &Cycle, threads: &str, ring: &str) -> Diagnostic {
    let first = &cx.m.waits[c.steps[0].0 as usize];
    match c.kind {
        CycleKind::Call if c.steps.len() == 1 => cx.diagnostic(
            &d101_call_cycle::CHECK,
            c,
            format!(
                "deadlock: `{}` calls a service that its own thread container {} must run",
                cx.app.path(first.root),
                cx.thread(first.ec)
            ),
        ),
        CycleKind::Call => cx.diagnostic(&d101_call_cycle::CHECK, c, format!("deadlock: synchronous calls of {threads} wait for each other: {ring}")),
        CycleKind::Response => cx.diagnostic(
            &d102_response_context::CHECK,
            c,
            format!(
                "deadlock: the response of this call must be processed by {}, which is blocked waiting for it",
                cx.thread(first.ec)
            ),
        ),
        CycleKind::Lock => cx.diagnostic(&d103_lock_order_inversion::CHECK, c, format!("deadlock: {threads} take locks in opposite orders: {ring}")),
        CycleKind::Mixed => cx.diagnostic(&d105_mixed_wait_cycle::CHECK, c, format!("deadlock: {threads} wait for each other through locks and blocking steps: {ring}")),
        CycleKind::QueueEmpty => cx.diagnostic(
            &d106_empty_queue_ring::CHECK,
            c,
            format!("deadlock: a ring of blocking reads holds no item ({} tokens): {ring}", c.tokens),
        ),
        CycleKind::QueueFull => cx.diagnostic(&d107_full_queue_ring::CHECK, c, format!("deadlock: a ring of blocking queues can fill up: {ring}")),
        CycleKind::Pool => {
            let (p, workers, demand) = c.pool.unwrap_or((first.ec, 0, 0));
            cx.diagnostic(
                &d108_pool_exhaustion::CHECK,
                c,
                format!(
                    "deadlock: nested calls can park all {workers} workers of pool {} (up to {demand} at once)",
                    cx.thread(p)
                ),
            )
        }
        CycleKind::SelfQueue => self_queue_read(cx, c),
    }
}

/// A module blocking on a queue its own thread container writes (D110); only a
/// warning when the writer runs first but may skip its write.
fn self_queue_read(cx: &Ctx<'_>, c: &Cycle) -> Diagnostic {
    let first = &cx.m.waits[c.steps[0].0 as usize];
    let queue = match first.kind {
        WaitKind::Read { queue } => cx.queue(queue),
        _ => "its input".to_string(),
    };
    let d = cx.diagnostic(
            &d110_same_thread_queue_read::CHECK,
            c,
            if c.tokens == 0 {
                format!(
                    "deadlock: `{}` blocks reading {}, whose writers run later in the same thread container {}",
                    cx.app.path(first.root),
                    queue,
                    cx.thread(first.ec)
                )
            } else {
                format!(
                    "`{}` blocks reading {}; its writer in the same thread container {} runs first but may skip its write",
                    cx.app.path(first.root),
                    queue,
                    cx.thread(first.ec)
                )
            },
        );
    if c.tokens > 0 {
        d.severity(Severity::Warning)
    } else {
        d
    }
}
