//! Static deadlock analysis (area D), after `../shared/design/reference/deadlocks.md` §2.
//!
//! 1. [`build`]: execution contexts (thread containers; exclusive unless `pool="n"`),
//!    locks, queues and the wait-states of every activity and service body, each with the
//!    set it holds (its own context as a pseudo-lock, plus the locks taken before it).
//! 2. [`solve`]: the wait-for graph (wait-states, context/lock hubs, queue hubs) with AND
//!    and OR waits, the greatest "can stay blocked forever" set by a linear counter
//!    fixpoint, then Tarjan SCCs of that set.
//! 3. [`witness`]: a bounded search inside each non-trivial SCC for a consistent cycle
//!    (distinct threads, disjoint holdings, queue states, the marked-graph token rule).
//! 4. [`dead_and_latent`]: trigger cycles that never start, latent lock-order inversions.
//!
//! Everything is linear in the model except the witness search, which is capped per SCC.
//! The result is a value ([`Analysis`]); the checks in `checks/deadlocks/` render it.

#![forbid(unsafe_code)]

mod build;
mod dead_and_latent;
mod follow;
pub mod render;
mod solve;
mod witness;

use ferroc_diagnostics::source::Span;
use ferroc_model::ir::{Application, ElementId};
use ferroc_model::library::LibrarySet;

pub type EcId = u32;
pub type WaitId = u32;
pub type QueueId = u32;

/// An execution context: one thread container.
#[derive(Debug, Clone)]
pub struct Ec {
    pub thread: ElementId,
    /// `pool="n"`: n workers, not a pseudo-lock.
    pub pool: Option<u32>,
    pub period: Option<f64>,
}

#[derive(Debug, Clone)]
pub struct Lock {
    pub name: String,
    /// The `<resource>` declaration, if there is one.
    pub span: Option<Span>,
    pub level: Option<u32>,
    pub recursive: bool,
}

/// The input side of a connection into a module input: a queue when some incoming
/// connection has `queue=`, a latest-value input otherwise.
#[derive(Debug, Clone)]
pub struct Queue {
    pub module: ElementId,
    pub port: u32,
    pub ec: Option<EcId>,
    pub is_queue: bool,
    pub capacity: Option<u32>,
    pub initial: u32,
    /// (module, output port, its context) of each writer.
    pub writers: Vec<(ElementId, u32, Option<EcId>)>,
    /// The `to` of a connection into it (or the module, when nothing is connected).
    pub span: Span,
    /// The `to` of a connection with `on-full="block"`.
    pub block_span: Option<Span>,
}

/// Something a wait-state holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Held {
    Ec(EcId),
    Lock(u32),
}

/// A service a client reaches.
#[derive(Debug, Clone)]
pub struct Target {
    pub module: ElementId,
    pub service: usize,
    pub ec: Option<EcId>,
    pub inline: bool,
    /// The `from` of the (first) `<connect>` from the client.
    pub connect: Span,
}

#[derive(Debug, Clone)]
pub enum WaitKind {
    /// A synchronous call (or await) without a server executing inline.
    Call {
        client: String,
        targets: Vec<Target>,
        /// `response-via="caller"`: the response needs this (the caller's) context.
        response: Option<EcId>,
    },
    Lock {
        lock: u32,
    },
    /// A write into one or more queues with `on-full="block"`.
    Write {
        port: u32,
        queues: Vec<QueueId>,
    },
    /// A blocking read.
    Read {
        queue: QueueId,
    },
}

/// A step that may block: (context, activity, step).
#[derive(Debug, Clone)]
pub struct Wait {
    pub ec: EcId,
    /// The module whose activity (or service) this is.
    pub root: ElementId,
    /// The module whose step it is (differs inside an inline service body).
    pub module: ElementId,
    pub activity: String,
    /// The service whose body this activity is.
    pub service: Option<(ElementId, usize)>,
    /// The inline service body the step belongs to, if any.
    pub inline: Option<(ElementId, usize)>,
    /// 1-based position in the activation (inline bodies counted in).
    pub step_no: u32,
    /// The step in the manifest.
    pub step_span: Span,
    /// The model element that makes it wait (a `<connect>`, a `<bind>`, the module).
    pub site: Span,
    pub kind: WaitKind,
    pub timeout: Option<f64>,
    /// Own-thread holdings, sorted.
    pub held: Vec<Held>,
    /// Holdings with where they were acquired.
    pub held_sites: Vec<(Held, Span)>,
    /// Outputs written earlier in the same activation.
    pub written_before: Vec<(ElementId, u32)>,
}

/// Findings about single steps, found while building.
#[derive(Debug, Clone)]
pub enum StepFindingKind {
    /// Taking a non-recursive lock already held (`first`: where it was taken).
    Recursive { lock: u32, first: Span },
    /// Taking `lock` while holding `outer` whose level is not higher.
    Level {
        lock: u32,
        outer: u32,
        outer_site: Span,
    },
    /// A synchronous call through an unconnected client (profiles where it fails at once).
    Unconnected { client: String },
}

#[derive(Debug, Clone)]
pub struct StepFinding {
    pub kind: StepFindingKind,
    pub module: ElementId,
    pub root: ElementId,
    pub ec: EcId,
    pub activity: String,
    pub step: Span,
    pub site: Span,
    pub inline: Option<(ElementId, usize)>,
}

/// The analysis model (output of [`build`]).
#[derive(Debug, Default)]
pub struct Model {
    pub ecs: Vec<Ec>,
    pub locks: Vec<Lock>,
    pub queues: Vec<Queue>,
    pub waits: Vec<Wait>,
    pub step_findings: Vec<StepFinding>,
}

/// How one wait-state reaches the next on a cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Hop {
    /// Waits for a context to run a service.
    Call,
    /// Waits for a worker of a saturated pool.
    Pool,
    /// The response must be processed by the caller's own context.
    Response,
    Lock(u32),
    /// Waits for space in a full queue.
    Full(QueueId),
    /// Waits for an item in an empty queue.
    Empty(QueueId),
}

/// What kind of cycle a witness is (one check each).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CycleKind {
    Call,
    Response,
    Lock,
    Mixed,
    QueueEmpty,
    QueueFull,
    Pool,
    SelfQueue,
}

/// One witness: a cycle of wait-states.
#[derive(Debug, Clone)]
pub struct Cycle {
    pub kind: CycleKind,
    /// Each wait-state with the hop that leaves it towards the next (the last returns).
    pub steps: Vec<(WaitId, Hop)>,
    /// Closed by one causal request chain (happens on every run).
    pub certain: bool,
    /// Found only with timed waits (a timeout breaks it).
    pub soft: bool,
    /// Consistency could not be established within the search budget.
    pub unverified: bool,
    /// For a read ring: the items on the ring; for a same-thread read: whether the
    /// earlier writer may skip its write (a warning, not an error).
    pub tokens: u32,
    pub may_skip: bool,
    /// Off-cycle writers that must also be blocked (OR waits), as wait-states.
    pub also_blocked: Vec<WaitId>,
    /// For a pool: workers and demand.
    pub pool: Option<(EcId, u32, u32)>,
}

/// A blocking wait nobody can ever end.
#[derive(Debug, Clone)]
pub struct Hang {
    pub wait: WaitId,
}

/// Trigger cycle of data-triggered modules that never run.
#[derive(Debug, Clone)]
pub struct DeadTrigger {
    /// The modules, in cycle order, with the connection (`to` span) into each.
    pub modules: Vec<(ElementId, Span)>,
}

/// A lock-order cycle that is not a deadlock only because of a shared guard.
#[derive(Debug, Clone)]
pub struct Latent {
    /// Lock-order edges: (wait-state taking the lock, lock held before it).
    pub edges: Vec<(WaitId, u32)>,
    pub guard: Held,
}

/// Everything the D checks report (about the [`Model`] it was computed from).
#[derive(Debug, Default)]
pub struct Analysis {
    pub cycles: Vec<Cycle>,
    pub hangs: Vec<Hang>,
    pub dead_triggers: Vec<DeadTrigger>,
    pub latent: Vec<Latent>,
}

/// Only the analysis model: contexts, locks, queues and wait-states (linear; no search).
/// The timing checks read the waits from it.
pub fn model(app: &Application, libs: &LibrarySet) -> Model {
    build::build(app, libs)
}

/// Runs the whole analysis on `model` (from [`model`]). Linear in the model, plus a
/// capped search per SCC.
pub fn analyse(app: &Application, libs: &LibrarySet, model: &Model) -> Analysis {
    let mut a = Analysis::default();
    if !model.waits.is_empty() {
        let hard = solve::solve(model, false);
        let mut covered = vec![false; model.waits.len()];
        for h in &hard.hangs {
            a.hangs.push(Hang { wait: *h });
        }
        for scc in &hard.sccs {
            if let Some(c) = witness::search(app, libs, model, &hard, scc, false) {
                for (w, _) in &c.steps {
                    covered[*w as usize] = true;
                }
                a.cycles.push(c);
            }
        }
        if model.waits.iter().any(|w| w.timeout.is_some()) {
            let soft = solve::solve(model, true);
            for scc in &soft.sccs {
                let has_soft = scc.iter().any(|&n| {
                    (n as usize) < model.waits.len() && model.waits[n as usize].timeout.is_some()
                });
                let overlaps = scc
                    .iter()
                    .any(|&n| (n as usize) < model.waits.len() && covered[n as usize]);
                if !has_soft || overlaps {
                    continue;
                }
                if let Some(c) = witness::search(app, libs, model, &soft, scc, true) {
                    if c.steps
                        .iter()
                        .any(|(w, _)| model.waits[*w as usize].timeout.is_some())
                    {
                        a.cycles.push(c);
                    }
                }
            }
        }
        a.latent = dead_and_latent::latent_inversions(model, &covered);
        self_queue_schedule(app, libs, model, &mut a.cycles);
    }
    a.dead_triggers = dead_and_latent::dead_triggers(app, libs);
    // A ring already reported as a deadlock is not reported again as never triggered.
    let in_cycle: hashbrown::HashSet<ElementId> = a
        .cycles
        .iter()
        .flat_map(|c| c.steps.iter().map(|(w, _)| model.waits[*w as usize].root))
        .collect();
    a.dead_triggers
        .retain(|d| !d.modules.iter().any(|(m, _)| in_cycle.contains(m)));
    a
}

/// A blocking read whose writers all run on the reader's own thread: a writer scheduled
/// earlier in the same cycle puts an item in first (`reference/deadlocks.md` DL-SELFQUEUE).
fn self_queue_schedule(app: &Application, libs: &LibrarySet, m: &Model, cycles: &mut Vec<Cycle>) {
    if !cycles.iter().any(|c| c.kind == CycleKind::SelfQueue) {
        return;
    }
    let schedule = ferroc_schedule::compute(app, libs);
    let position = |module: ElementId| {
        schedule
            .containers
            .iter()
            .find_map(|c| c.steps.iter().position(|s| s.module == module))
    };
    for c in cycles.iter_mut().filter(|c| c.kind == CycleKind::SelfQueue) {
        let wait = &m.waits[c.steps[0].0 as usize];
        let WaitKind::Read { queue } = wait.kind else {
            continue;
        };
        let reader_at = position(wait.root);
        for (writer, _, ec) in &m.queues[queue as usize].writers {
            if *writer != wait.root && *ec == Some(wait.ec) && position(*writer) < reader_at {
                c.tokens += 1;
                let port = m.queues[queue as usize]
                    .writers
                    .iter()
                    .find(|w| w.0 == *writer)
                    .map(|w| w.1);
                let optional = app.module_type(libs, *writer).is_some_and(|mt| {
                    mt.activities.iter().flat_map(|a| &a.steps).any(|s| {
                        matches!(s.op, ferroc_model::library::steps::StepOp::Write { port: p, optional: true, .. } if Some(p as u32) == port)
                    })
                });
                c.may_skip |= optional;
            }
        }
    }
    cycles.retain(|c| c.kind != CycleKind::SelfQueue || c.tokens == 0 || c.may_skip);
}
