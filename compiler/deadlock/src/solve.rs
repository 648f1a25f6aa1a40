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
    let nodes = Nodes::of(m);
    let (nw, n) = (m.waits.len(), nodes.count());
    let included: Vec<bool> = (0..n)
        .map(|i| i >= nw || soft || m.waits[i].timeout.is_none())
        .collect();
    let body = service_bodies(m, &included);
    let demand = pool_demand(m, &body, &included);
    let (lists, all) = wait_graph(m, &nodes, &body, &demand, &included);
    let (offsets, succ) = csr(&lists);
    drop(lists);
    let stuck = greatest_fixpoint(&offsets, &succ, &included, &all);
    let hangs = (0..nw)
        .filter(|&i| stuck[i] && included[i])
        .filter(|&i| match &m.waits[i].kind {
            WaitKind::Call { targets, .. } => targets.is_empty(),
            WaitKind::Read { queue } => {
                let d = nodes.q_data(*queue) as usize;
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

/// The node numbering: wait-states, then the hubs of contexts, locks, queue data and
/// queue space.
struct Nodes {
    nw: usize,
    ne: usize,
    nl: usize,
    nq: usize,
}

impl Nodes {
    fn of(m: &Model) -> Self {
        Nodes {
            nw: m.waits.len(),
            ne: m.ecs.len(),
            nl: m.locks.len(),
            nq: m.queues.len(),
        }
    }

    fn count(&self) -> usize {
        self.nw + self.ne + self.nl + 2 * self.nq
    }

    fn ec_hub(&self, e: EcId) -> u32 {
        (self.nw + e as usize) as u32
    }

    fn lock_hub(&self, l: u32) -> u32 {
        (self.nw + self.ne + l as usize) as u32
    }

    fn q_data(&self, q: u32) -> u32 {
        (self.nw + self.ne + self.nl + q as usize) as u32
    }

    fn q_space(&self, q: u32) -> u32 {
        (self.nw + self.ne + self.nl + self.nq + q as usize) as u32
    }
}

/// Service (module, index) → the wait-states of its body.
type ServiceBodies = HashMap<(ferroc_model::ir::ElementId, usize), Vec<WaitId>>;

/// Service → the wait-states of its body (for calls into pools).
fn service_bodies(m: &Model, included: &[bool]) -> ServiceBodies {
    let mut body = ServiceBodies::new();
    for (i, w) in m.waits.iter().enumerate() {
        if let (Some(s), None) = (w.service, w.inline) {
            if included[i] {
                body.entry(s).or_default().push(i as WaitId);
            }
        }
    }
    body
}

/// The successor list of every node, and which nodes are ALL nodes (stuck only when
/// every successor is).
fn wait_graph(
    m: &Model,
    nodes: &Nodes,
    body: &ServiceBodies,
    demand: &[u32],
    included: &[bool],
) -> (Vec<Vec<u32>>, Vec<bool>) {
    let n = nodes.count();
    let mut all = vec![false; n];
    let mut lists: Vec<Vec<u32>> = vec![Vec::new(); n];
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
                    out.push(nodes.ec_hub(ec));
                    if m.ecs[ec as usize].pool.is_some() {
                        out.extend(body.get(&(t.module, t.service)).into_iter().flatten());
                    }
                }
                if let Some(r) = response {
                    out.push(nodes.ec_hub(*r));
                }
            }
            WaitKind::Lock { lock } => out.push(nodes.lock_hub(*lock)),
            WaitKind::Write { queues, .. } => out.extend(queues.iter().map(|q| nodes.q_space(*q))),
            WaitKind::Read { queue } => {
                all[i] = true;
                out.push(nodes.q_data(*queue));
            }
        }
        for h in &w.held {
            let hub = match *h {
                Held::Ec(e) => nodes.ec_hub(e),
                Held::Lock(l) => nodes.lock_hub(l),
            };
            lists[hub as usize].push(i as u32);
        }
        if let Some(p) = m.ecs[w.ec as usize].pool {
            if demand[w.ec as usize] >= p {
                lists[nodes.ec_hub(w.ec) as usize].push(i as u32);
            }
        }
    }
    for (q, queue) in m.queues.iter().enumerate() {
        let data = nodes.q_data(q as u32) as usize;
        all[data] = true;
        let mut ecs: Vec<EcId> = queue.writers.iter().filter_map(|w| w.2).collect();
        ecs.sort_unstable();
        ecs.dedup();
        lists[data].extend(ecs.into_iter().map(|e| nodes.ec_hub(e)));
        if let Some(ec) = queue.ec {
            lists[nodes.q_space(q as u32) as usize].push(nodes.ec_hub(ec));
        }
    }
    (lists, all)
}

/// The successor lists in CSR form: offsets (one more than nodes) and successors.
fn csr(lists: &[Vec<u32>]) -> (Vec<u32>, Vec<u32>) {
    let mut offsets = Vec::with_capacity(lists.len() + 1);
    let mut succ = Vec::new();
    offsets.push(0u32);
    for l in lists {
        succ.extend_from_slice(l);
        offsets.push(succ.len() as u32);
    }
    (offsets, succ)
}

/// The greatest stuck set: start with every included node stuck and free nodes with a
/// worklist over the predecessors.
fn greatest_fixpoint(offsets: &[u32], succ: &[u32], included: &[bool], all: &[bool]) -> Vec<bool> {
    let n = offsets.len() - 1;
    // Predecessors (CSR) for the worklist.
    let mut pred_count = vec![0u32; n + 1];
    for &t in succ {
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
    let mut stuck = included.to_vec();
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
    stuck
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
fn pool_demand(m: &Model, body: &ServiceBodies, included: &[bool]) -> Vec<u32> {
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
    body: &ServiceBodies,
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
