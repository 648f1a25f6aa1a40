//! The wait-for graph, the greatest "can stay blocked forever" set and its SCCs
//! (`reference/deadlocks.md` §2.3–2.4 steps 2–3).
//!
//! Nodes: wait-states, then one hub per context, per lock, and two per queue (`data`:
//! someone will write; `space`: someone will drain). An ANY node is stuck when some
//! successor is stuck (a call, a lock, a write: AND-waits), an ALL node when every
//! successor is (a read fed by several writers: an OR-wait). Terminal ALL nodes stay
//! stuck (nobody can end the wait). Start with everything stuck and remove nodes with a
//! worklist: O(V + E).

use super::{EcId, Held, Model, WaitId, WaitKind};
use hashbrown::HashMap;
use petgraph::graph::{DiGraph, NodeIndex};

pub(super) struct Solved {
    pub n_waits: usize,
    /// CSR successors.
    pub offsets: Vec<u32>,
    pub succ: Vec<u32>,
    /// Non-trivial SCCs of the stuck set (node ids, sorted).
    pub sccs: Vec<Vec<u32>>,
    /// Waits nobody can end (no writer, no server).
    pub hangs: Vec<WaitId>,
    /// Per context: demand on a pool (0 for exclusive contexts).
    pub demand: Vec<u32>,
}

impl Solved {
    pub fn successors(&self, n: u32) -> &[u32] {
        &self.succ[self.offsets[n as usize] as usize..self.offsets[n as usize + 1] as usize]
    }
}

pub(super) fn solve(m: &Model, soft: bool) -> Solved {
    let (nw, ne, nl, nq) = (m.waits.len(), m.ecs.len(), m.locks.len(), m.queues.len());
    let ec_hub = |e: EcId| (nw + e as usize) as u32;
    let lock_hub = |l: u32| (nw + ne + l as usize) as u32;
    let q_data = |q: u32| (nw + ne + nl + q as usize) as u32;
    let q_space = |q: u32| (nw + ne + nl + nq + q as usize) as u32;
    let n = nw + ne + nl + 2 * nq;
    let included: Vec<bool> = (0..n)
        .map(|i| i >= nw || soft || m.waits[i].timeout.is_none())
        .collect();
    let mut all = vec![false; n];
    let mut lists: Vec<Vec<u32>> = vec![Vec::new(); n];
    // Service → the wait-states of its body (for calls into pools).
    let mut body: HashMap<(ferroc_model::ir::ElementId, usize), Vec<WaitId>> = HashMap::new();
    for (i, w) in m.waits.iter().enumerate() {
        if let (Some(s), None) = (w.service, w.inline) {
            if included[i] {
                body.entry(s).or_default().push(i as WaitId);
            }
        }
    }
    let demand = pool_demand(m, &body, &included);
    for (i, w) in m.waits.iter().enumerate() {
        if !included[i] {
            continue;
        }
        let out = &mut lists[i];
        match &w.kind {
            WaitKind::Call {
                targets, response, ..
            } => {
                if targets.is_empty() {
                    all[i] = true; // nobody serves it: terminal
                }
                for t in targets {
                    let Some(ec) = t.ec else { continue };
                    out.push(ec_hub(ec));
                    if m.ecs[ec as usize].pool.is_some() {
                        out.extend(body.get(&(t.module, t.service)).into_iter().flatten());
                    }
                }
                if let Some(r) = response {
                    out.push(ec_hub(*r));
                }
            }
            WaitKind::Lock { lock } => out.push(lock_hub(*lock)),
            WaitKind::Write { queues, .. } => out.extend(queues.iter().map(|q| q_space(*q))),
            WaitKind::Read { queue } => {
                all[i] = true;
                out.push(q_data(*queue));
            }
        }
        for h in &w.held {
            let hub = match *h {
                Held::Ec(e) => ec_hub(e),
                Held::Lock(l) => lock_hub(l),
            };
            lists[hub as usize].push(i as u32);
        }
        if let Some(p) = m.ecs[w.ec as usize].pool {
            if demand[w.ec as usize] >= p {
                lists[ec_hub(w.ec) as usize].push(i as u32);
            }
        }
    }
    for (q, queue) in m.queues.iter().enumerate() {
        let data = q_data(q as u32) as usize;
        all[data] = true;
        let mut ecs: Vec<EcId> = queue.writers.iter().filter_map(|w| w.2).collect();
        ecs.sort_unstable();
        ecs.dedup();
        lists[data].extend(ecs.into_iter().map(ec_hub));
        if let Some(ec) = queue.ec {
            lists[q_space(q as u32) as usize].push(ec_hub(ec));
        }
    }
    let mut offsets = Vec::with_capacity(n + 1);
    let mut succ = Vec::new();
    offsets.push(0u32);
    for l in &lists {
        succ.extend_from_slice(l);
        offsets.push(succ.len() as u32);
    }
    drop(lists);
    // Predecessors (CSR) for the worklist.
    let mut pred_count = vec![0u32; n + 1];
    for &t in &succ {
        pred_count[t as usize + 1] += 1;
    }
    for i in 0..n {
        pred_count[i + 1] += pred_count[i];
    }
    let mut pred = vec![0u32; succ.len()];
    let mut fill = pred_count.clone();
    for s in 0..n {
        for &t in &succ[offsets[s] as usize..offsets[s + 1] as usize] {
            pred[fill[t as usize] as usize] = s as u32;
            fill[t as usize] += 1;
        }
    }
    // Greatest fixpoint.
    let mut stuck = included.clone();
    let mut count: Vec<u32> = (0..n).map(|i| offsets[i + 1] - offsets[i]).collect();
    let mut work: Vec<u32> = Vec::new();
    for i in 0..n {
        if stuck[i] && !all[i] && count[i] == 0 {
            stuck[i] = false;
            work.push(i as u32);
        }
    }
    // (Excluded waits have no edges at all: nothing needs to notice them.)
    while let Some(v) = work.pop() {
        for &u in &pred[pred_count[v as usize] as usize..pred_count[v as usize + 1] as usize] {
            let u = u as usize;
            if !stuck[u] {
                continue;
            }
            if all[u] {
                stuck[u] = false;
                work.push(u as u32);
            } else {
                count[u] -= 1;
                if count[u] == 0 {
                    stuck[u] = false;
                    work.push(u as u32);
                }
            }
        }
    }
    let hangs = (0..nw)
        .filter(|&i| stuck[i] && included[i])
        .filter(|&i| match &m.waits[i].kind {
            WaitKind::Call { targets, .. } => targets.is_empty(),
            WaitKind::Read { queue } => {
                let d = q_data(*queue) as usize;
                offsets[d] == offsets[d + 1]
            }
            _ => false,
        })
        .map(|i| i as WaitId)
        .collect();
    let sccs = sccs(n, &offsets, &succ, &stuck);
    Solved {
        n_waits: nw,
        offsets,
        succ,
        sccs,
        hangs,
        demand,
    }
}

/// Tarjan on the stuck subgraph; only SCCs that can hold a cycle.
fn sccs(n: usize, offsets: &[u32], succ: &[u32], stuck: &[bool]) -> Vec<Vec<u32>> {
    let mut g: DiGraph<u32, ()> = DiGraph::new();
    let mut idx = vec![NodeIndex::end(); n];
    for i in (0..n).filter(|&i| stuck[i]) {
        idx[i] = g.add_node(i as u32);
    }
    for i in (0..n).filter(|&i| stuck[i]) {
        for &t in &succ[offsets[i] as usize..offsets[i + 1] as usize] {
            if stuck[t as usize] {
                g.add_edge(idx[i], idx[t as usize], ());
            }
        }
    }
    let mut out: Vec<Vec<u32>> = petgraph::algo::tarjan_scc(&g)
        .into_iter()
        .filter(|c| c.len() > 1 || g.contains_edge(c[0], c[0]))
        .map(|c| {
            let mut v: Vec<u32> = c.into_iter().map(|x| g[x]).collect();
            v.sort_unstable();
            v
        })
        .collect();
    out.sort();
    out
}

/// demand(P) = Σ over callers from outside P of c · (L − 1), where c is the caller's
/// concurrency and L the longest chain of synchronous calls that stays inside P.
fn pool_demand(
    m: &Model,
    body: &HashMap<(ferroc_model::ir::ElementId, usize), Vec<WaitId>>,
    included: &[bool],
) -> Vec<u32> {
    let mut demand = vec![0u32; m.ecs.len()];
    if m.ecs.iter().all(|e| e.pool.is_none()) {
        return demand;
    }
    let mut memo: HashMap<(ferroc_model::ir::ElementId, usize), u32> = HashMap::new();
    for (i, w) in m.waits.iter().enumerate() {
        let WaitKind::Call { targets, .. } = &w.kind else {
            continue;
        };
        if !included[i] {
            continue;
        }
        for t in targets {
            let Some(p) = t.ec else { continue };
            let Some(n) = m.ecs[p as usize].pool else {
                continue;
            };
            if p == w.ec {
                continue; // chains inside the pool are counted in L
            }
            let c = m.ecs[w.ec as usize].pool.unwrap_or(1);
            let l = chain(
                m,
                body,
                p,
                (t.module, t.service),
                &mut memo,
                &mut Vec::new(),
                n,
            );
            demand[p as usize] = demand[p as usize].saturating_add(c.saturating_mul(l - 1));
        }
    }
    demand
}

fn chain(
    m: &Model,
    body: &HashMap<(ferroc_model::ir::ElementId, usize), Vec<WaitId>>,
    pool: EcId,
    s: (ferroc_model::ir::ElementId, usize),
    memo: &mut HashMap<(ferroc_model::ir::ElementId, usize), u32>,
    stack: &mut Vec<(ferroc_model::ir::ElementId, usize)>,
    n: u32,
) -> u32 {
    if let Some(&l) = memo.get(&s) {
        return l;
    }
    if stack.contains(&s) || stack.len() > 64 {
        return n + 1; // recursive: unbounded
    }
    stack.push(s);
    let mut best = 1u32;
    for &w in body.get(&s).into_iter().flatten() {
        if let WaitKind::Call { targets, .. } = &m.waits[w as usize].kind {
            for t in targets.iter().filter(|t| t.ec == Some(pool)) {
                let l = chain(m, body, pool, (t.module, t.service), memo, stack, n);
                best = best.max(l.saturating_add(1));
            }
        }
    }
    stack.pop();
    memo.insert(s, best);
    best
}
