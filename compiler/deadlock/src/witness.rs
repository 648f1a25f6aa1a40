//! The bounded witness search inside one SCC (`reference/deadlocks.md` §2.4 step 4, §2.5).
//!
//! A witness is a cycle of wait-states, hubs collapsed into hops. It is consistent when
//! the wait-states hold pairwise disjoint sets (so they are on distinct threads and no
//! common gate lock serialises them), no queue is both full and empty, and queue hops
//! pass the marked-graph token rule. Shortest cycles first (iterative deepening), from
//! the smallest wait-state, within a budget of node expansions; when the budget or the
//! length cap cuts the search short, the shortest unconstrained cycle is reported as
//! unverified instead of staying silent.

use super::solve::Solved;
use super::{Cycle, CycleKind, Hop, Model, WaitId, WaitKind};
use ferroc_model::ir::Application;
use ferroc_model::library::LibrarySet;

const MAX_LEN: usize = 12;
const BUDGET: u32 = 100_000;

pub(super) fn search(
    app: &Application,
    libs: &LibrarySet,
    m: &Model,
    s: &Solved,
    scc: &[u32],
    soft: bool,
) -> Option<Cycle> {
    let in_scc = |n: u32| scc.binary_search(&n).is_ok();
    let waits: Vec<WaitId> = scc
        .iter()
        .copied()
        .filter(|&n| (n as usize) < s.n_waits)
        .collect();
    if waits.is_empty() {
        return None;
    }
    // Wait-level successors through hubs, inside the SCC.
    let next = |w: WaitId| -> Vec<(WaitId, Hop)> { next_waits(m, s, w, &in_scc) };
    let mut ctx = Search {
        m,
        app,
        libs,
        budget: BUDGET,
        cut: false,
        next: &next,
    };
    for len in 1..=MAX_LEN {
        for &start in &waits {
            let mut path = vec![];
            if let Some(c) = ctx.dfs(start, start, len, &mut path) {
                return Some(finish(app, libs, m, s, c, soft, false));
            }
            if ctx.budget == 0 {
                break;
            }
        }
        if ctx.budget == 0 {
            break;
        }
    }
    if !ctx.cut && ctx.budget > 0 {
        return None; // every cycle is inconsistent: not a deadlock
    }
    let c = shortest_cycle(&waits, &next)?;
    Some(finish(app, libs, m, s, c, soft, true))
}

fn next_waits(
    m: &Model,
    s: &Solved,
    w: WaitId,
    in_scc: &dyn Fn(u32) -> bool,
) -> Vec<(WaitId, Hop)> {
    let nw = s.n_waits as u32;
    let (ne, nl, nq) = (
        m.ecs.len() as u32,
        m.locks.len() as u32,
        m.queues.len() as u32,
    );
    let wait = &m.waits[w as usize];
    let mut out = Vec::new();
    for &h in s.successors(w) {
        if !in_scc(h) {
            continue;
        }
        if h < nw {
            out.push((h, Hop::Pool));
            continue;
        }
        let hub = h - nw;
        let (hop, ecs): (Hop, Vec<u32>) = if hub < ne {
            let hop = match &wait.kind {
                WaitKind::Call { response, .. } if *response == Some(hub) && hub == wait.ec => {
                    Hop::Response
                }
                WaitKind::Call { .. } if m.ecs[hub as usize].pool.is_some() => Hop::Pool,
                _ => Hop::Call,
            };
            (hop, vec![h])
        } else if hub < ne + nl {
            (Hop::Lock(hub - ne), vec![h])
        } else if hub < ne + nl + nq {
            let q = hub - ne - nl;
            (
                Hop::Empty(q),
                s.successors(h)
                    .iter()
                    .copied()
                    .filter(|&x| in_scc(x))
                    .collect(),
            )
        } else {
            let q = hub - ne - nl - nq;
            (
                Hop::Full(q),
                s.successors(h)
                    .iter()
                    .copied()
                    .filter(|&x| in_scc(x))
                    .collect(),
            )
        };
        for e in ecs {
            for &x in s.successors(e) {
                if x < nw && in_scc(x) && !out.iter().any(|(y, hp)| *y == x && *hp == hop) {
                    out.push((x, hop));
                }
            }
        }
    }
    out
}

struct Search<'a> {
    m: &'a Model,
    app: &'a Application,
    libs: &'a LibrarySet,
    budget: u32,
    /// Some path was cut by the length cap.
    cut: bool,
    next: &'a dyn Fn(WaitId) -> Vec<(WaitId, Hop)>,
}

impl Search<'_> {
    /// Cycles of exactly `len` wait-states through `start`, all others > `start`.
    fn dfs(
        &mut self,
        start: WaitId,
        at: WaitId,
        len: usize,
        path: &mut Vec<(WaitId, Hop)>,
    ) -> Option<Vec<(WaitId, Hop)>> {
        if self.budget == 0 {
            return None;
        }
        self.budget -= 1;
        for (nx, hop) in (self.next)(at) {
            path.push((at, hop));
            if nx == start && path.len() == len {
                if consistent_queues(path)
                    && token_rule(self.app, self.libs, self.m, path).is_some()
                {
                    return Some(path.clone());
                }
            } else if nx > start && path.len() < len && !path.iter().any(|(w, _)| *w == nx) {
                if compatible(self.m, path, nx) && consistent_queues(path) {
                    if let Some(c) = self.dfs(start, nx, len, path) {
                        return Some(c);
                    }
                }
            } else if nx > start && path.len() == len && len == MAX_LEN {
                self.cut = true;
            }
            path.pop();
        }
        None
    }
}

/// `nx` holds nothing any wait-state on the path holds (generalised GoodLock).
fn compatible(m: &Model, path: &[(WaitId, Hop)], nx: WaitId) -> bool {
    let h = &m.waits[nx as usize].held;
    path.iter().all(|(w, _)| {
        let o = &m.waits[*w as usize].held;
        !h.iter().any(|x| o.binary_search(x).is_ok())
    })
}

/// No queue is both full (a write hop) and empty (a read hop).
fn consistent_queues(path: &[(WaitId, Hop)]) -> bool {
    path.iter().all(|(_, h)| match h {
        Hop::Full(q) => !path.iter().any(|(_, x)| *x == Hop::Empty(*q)),
        _ => true,
    })
}

/// The marked-graph rule for the queue hops of a closed cycle. `Some((tokens, may_skip,
/// certain))` when the cycle can deadlock, `None` when the rule proves it cannot.
fn token_rule(
    app: &Application,
    libs: &LibrarySet,
    m: &Model,
    cycle: &[(WaitId, Hop)],
) -> Option<(u32, bool, bool)> {
    let queue_hops = cycle
        .iter()
        .filter(|(_, h)| matches!(h, Hop::Full(_) | Hop::Empty(_)))
        .count();
    if queue_hops == 0 {
        return Some((0, false, false));
    }
    let k = cycle.len();
    let c = QueueCycle {
        app,
        libs,
        m,
        cycle,
        queues: cycle
            .iter()
            .filter_map(|(w, h)| match h {
                Hop::Empty(q) => Some(*q),
                Hop::Full(_) => write_queue(m, *w, cycle),
                _ => None,
            })
            .collect(),
    };
    let all_reads = cycle.iter().all(|(_, h)| matches!(h, Hop::Empty(_)));
    let only_queues = queue_hops == k;
    if all_reads {
        let mut total = 0;
        let mut skip = false;
        for (i, (_, h)) in cycle.iter().enumerate() {
            if let Hop::Empty(q) = h {
                let (t, s) = c.tokens_of(i, *q);
                total += t;
                skip |= s;
            }
        }
        if k == 1 {
            return Some((total, skip, total == 0)); // same thread: decided by the caller
        }
        return (total == 0 || skip).then_some((total, skip, total == 0 && !skip));
    }
    if only_queues {
        let any = cycle
            .iter()
            .any(|(w, h)| matches!(h, Hop::Full(_)) && c.over_producing(*w));
        return any.then_some((0, false, false));
    }
    // Mixed with locks or calls: each queue hop must be fillable or drainable on its own.
    for (i, (w, h)) in cycle.iter().enumerate() {
        match h {
            Hop::Full(_) if !c.over_producing(*w) => return None,
            Hop::Empty(q) if c.tokens_of(i, *q).0 > 0 => return None,
            _ => {}
        }
    }
    Some((0, false, false))
}

/// A closed cycle with queue hops, and the queues it goes through.
struct QueueCycle<'a> {
    app: &'a Application,
    libs: &'a LibrarySet,
    m: &'a Model,
    cycle: &'a [(WaitId, Hop)],
    queues: Vec<u32>,
}

impl QueueCycle<'_> {
    /// Items the read hop `i` on queue `q` sees: initial ones plus a write earlier in
    /// the writer's activation; and whether the writer may skip its write.
    fn tokens_of(&self, i: usize, q: u32) -> (u32, bool) {
        let (m, cycle) = (self.m, self.cycle);
        let k = cycle.len();
        let queue = &m.queues[q as usize];
        let writer = &m.waits[cycle[(i + 1) % k].0 as usize];
        let mut t = queue.initial;
        let mut skip = false;
        for (wm, wp, _) in &queue.writers {
            if writer.written_before.contains(&(*wm, *wp)) {
                t += 1;
            }
            if *wm == writer.root {
                let sum = m.activity_summary(self.app, self.libs, cycle[(i + 1) % k].0);
                skip |= sum
                    .writes
                    .iter()
                    .any(|(p, c, opt)| p == wp && (*opt || *c == 0));
            }
        }
        (t, skip)
    }

    /// A writer is over-producing unless it is conserving on the cycle.
    fn over_producing(&self, w: WaitId) -> bool {
        let m = self.m;
        let wait = &m.waits[w as usize];
        let WaitKind::Write { port, queues } = &wait.kind else {
            return false;
        };
        let sum = m.activity_summary(self.app, self.libs, w);
        let batch = sum
            .writes
            .iter()
            .any(|(p, c, opt)| p == port && (*c > 1 || *opt));
        let second_writer = queues
            .iter()
            .any(|q| m.queues[*q as usize].writers.len() > 1);
        let paired = self.queues.iter().any(|q| {
            let queue = &m.queues[*q as usize];
            queue.module == wait.root && sum.blocking_reads.contains(&queue.port)
        });
        batch || second_writer || !paired
    }
}

/// The queue a write hop waits on (the one whose reader is the next wait-state).
fn write_queue(m: &Model, w: WaitId, cycle: &[(WaitId, Hop)]) -> Option<u32> {
    let i = cycle.iter().position(|(x, _)| *x == w)?;
    let next = &m.waits[cycle[(i + 1) % cycle.len()].0 as usize];
    let WaitKind::Write { queues, .. } = &m.waits[w as usize].kind else {
        return None;
    };
    queues
        .iter()
        .copied()
        .find(|q| m.queues[*q as usize].ec == Some(next.ec))
}

fn shortest_cycle(
    waits: &[WaitId],
    next: &dyn Fn(WaitId) -> Vec<(WaitId, Hop)>,
) -> Option<Vec<(WaitId, Hop)>> {
    for &start in waits {
        let mut prev: hashbrown::HashMap<WaitId, (WaitId, Hop)> = Default::default();
        let mut queue = std::collections::VecDeque::from([start]);
        while let Some(at) = queue.pop_front() {
            for (nx, hop) in next(at) {
                if nx == start {
                    let mut path = vec![(at, hop)];
                    let mut cur = at;
                    while cur != start {
                        let (p, h) = prev[&cur];
                        path.push((p, h));
                        cur = p;
                    }
                    path.reverse();
                    return Some(path);
                }
                if !prev.contains_key(&nx) {
                    prev.insert(nx, (at, hop));
                    queue.push_back(nx);
                }
            }
        }
    }
    None
}

fn finish(
    app: &Application,
    libs: &LibrarySet,
    m: &Model,
    s: &Solved,
    mut steps: Vec<(WaitId, Hop)>,
    soft: bool,
    unverified: bool,
) -> Cycle {
    // Write hops name their queue.
    let fixed: Vec<(WaitId, Hop)> = steps
        .iter()
        .map(|(w, h)| match h {
            Hop::Full(_) => (*w, Hop::Full(write_queue(m, *w, &steps).unwrap_or(0))),
            _ => (*w, *h),
        })
        .collect();
    steps = fixed;
    let (tokens, may_skip, queue_certain) =
        token_rule(app, libs, m, &steps).unwrap_or((0, false, false));
    // Rotate: a causal chain starts at its first call; otherwise at the smallest thread path.
    let k = steps.len();
    let chain_start = (0..k).find(|&r| is_chain(m, &steps, r));
    let start = chain_start.unwrap_or_else(|| {
        (0..k)
            .min_by_key(|&i| app.path(m.ecs[m.waits[steps[i].0 as usize].ec as usize].thread))
            .unwrap_or(0)
    });
    steps.rotate_left(start);
    let hops: Vec<Hop> = steps.iter().map(|(_, h)| *h).collect();
    let kind = if hops.contains(&Hop::Response) {
        CycleKind::Response
    } else if hops.contains(&Hop::Pool) {
        CycleKind::Pool
    } else if hops.iter().all(|h| *h == Hop::Call) {
        CycleKind::Call
    } else if hops.iter().all(|h| matches!(h, Hop::Lock(_))) {
        CycleKind::Lock
    } else if hops.iter().all(|h| matches!(h, Hop::Empty(_))) {
        if k == 1 {
            CycleKind::SelfQueue
        } else {
            CycleKind::QueueEmpty
        }
    } else if hops
        .iter()
        .all(|h| matches!(h, Hop::Empty(_) | Hop::Full(_)))
    {
        CycleKind::QueueFull
    } else {
        CycleKind::Mixed
    };
    let pool = steps.iter().find_map(|(w, h)| {
        if *h != Hop::Pool {
            return None;
        }
        let WaitKind::Call { targets, .. } = &m.waits[*w as usize].kind else {
            return None;
        };
        let p = targets
            .iter()
            .find_map(|t| t.ec.filter(|e| m.ecs[*e as usize].pool.is_some()))?;
        Some((p, m.ecs[p as usize].pool.unwrap_or(0), s.demand[p as usize]))
    });
    let certain = chain_start.is_some() || (kind == CycleKind::QueueEmpty && queue_certain);
    Cycle {
        kind,
        steps,
        certain,
        soft,
        unverified,
        tokens,
        may_skip,
        also_blocked: Vec::new(),
        pool,
    }
}

/// From rotation `r`: the first wait-state is a call and each next one lies in the body
/// of the service the previous one calls (one causal request chain).
fn is_chain(m: &Model, steps: &[(WaitId, Hop)], r: usize) -> bool {
    let k = steps.len();
    let first = &m.waits[steps[r].0 as usize];
    if !matches!(first.kind, WaitKind::Call { .. }) {
        return false;
    }
    (0..k - 1).all(|i| {
        let cur = &m.waits[steps[(r + i) % k].0 as usize];
        let nx = &m.waits[steps[(r + i + 1) % k].0 as usize];
        match &cur.kind {
            WaitKind::Call { targets, .. } => targets
                .iter()
                .any(|t| nx.service == Some((t.module, t.service))),
            _ => false,
        }
    })
}
