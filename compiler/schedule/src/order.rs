//! Ordering the steps of one thread container: classification into sets, then a
//! deterministic topological sort per set that breaks loops at one edge.

use super::{BrokenEdge, ContainerSchedule, DataEdge, Step, StepKind, StepSet};
use ferroc_model::ir::{Application, ElementId};
use hashbrown::HashMap;
use std::cmp::Reverse;
use std::collections::{BTreeSet, BinaryHeap};

// Flags from flooding along data edges (FINROC's names).
const SENSE_DEPENDENT: u8 = 1; // reached forward from a sense step
const SENSE_DEPENDENCY: u8 = 2; // reaches a sense step
const CONTROL_DEPENDENT: u8 = 4;
const CONTROL_DEPENDENCY: u8 = 8;

/// The set an update step belongs to, from its flags. Anything feeding both sensing and
/// control runs first; a step between sensing and control runs with sensing; a step only
/// around control runs with control; an unrelated one runs last.
pub fn classify(flags: u8) -> StepSet {
    let has = |f: u8| flags & f != 0;
    if has(SENSE_DEPENDENCY) && has(CONTROL_DEPENDENCY) {
        StepSet::Initial
    } else if has(SENSE_DEPENDENCY) || has(SENSE_DEPENDENT) {
        StepSet::Sense
    } else if has(CONTROL_DEPENDENCY) || has(CONTROL_DEPENDENT) {
        StepSet::Control
    } else {
        StepSet::Other
    }
}

/// One container: `steps` lists each module's steps, `edges` the data edges whose both
/// ends are executed by this container.
pub fn schedule_container(
    app: &Application,
    thread: ElementId,
    steps: Vec<(ElementId, StepKind)>,
    edges: &[&DataEdge],
) -> ContainerSchedule {
    let links = step_links(&steps, edges);
    let sets = assign_sets(&steps, &links);
    let rank = ranks(app, &steps, &sets);
    let step = |i: usize| Step {
        module: steps[i].0,
        kind: steps[i].1,
        set: sets[i],
    };
    let mut pairs = pairs_within_sets(links, &sets);
    let order = topological(&rank, &mut pairs);
    let broken = order
        .broken
        .iter()
        .map(|(p, cycle)| {
            let pr = &pairs[*p];
            BrokenEdge {
                from: step(pr.from),
                to: step(pr.to),
                edge: pr.edge.clone(),
                cycle: cycle
                    .iter()
                    .map(|q| (step(pairs[*q].from), pairs[*q].edge.clone()))
                    .collect(),
                inhibition: pr.inhibition,
            }
        })
        .collect();
    ContainerSchedule {
        thread,
        steps: order.sequence.into_iter().map(step).collect(),
        broken,
    }
}

/// Step-level edges: the steps (indexes into `steps`) each data edge runs between.
/// Delayed edges are intended feedback: no constraint at all.
fn step_links<'e>(
    steps: &[(ElementId, StepKind)],
    edges: &[&'e DataEdge],
) -> Vec<(usize, usize, &'e DataEdge)> {
    let index: HashMap<(ElementId, StepKind), usize> =
        steps.iter().enumerate().map(|(i, s)| (*s, i)).collect();
    let sensing: hashbrown::HashSet<ElementId> = steps
        .iter()
        .filter(|(_, k)| *k == StepKind::Sense)
        .map(|(m, _)| *m)
        .collect();
    let mut links: Vec<(usize, usize, &DataEdge)> = Vec::new();
    for e in edges.iter().filter(|e| !e.delayed) {
        let from = super::step_of(e.from_role, sensing.contains(&e.from_module));
        let to = super::step_of(e.to_role, sensing.contains(&e.to_module));
        if let (Some(&a), Some(&b)) = (
            index.get(&(e.from_module, from)),
            index.get(&(e.to_module, to)),
        ) {
            links.push((a, b, e));
        }
    }
    links
}

/// Rank = position in (set, path, kind) order: the tie-break of the sort.
fn ranks(app: &Application, steps: &[(ElementId, StepKind)], sets: &[StepSet]) -> Vec<usize> {
    let paths: Vec<String> = steps.iter().map(|(m, _)| app.path(*m)).collect();
    let mut by_key: Vec<usize> = (0..steps.len()).collect();
    by_key
        .sort_by(|&a, &b| (sets[a], &paths[a], steps[a].1).cmp(&(sets[b], &paths[b], steps[b].1)));
    let mut rank = vec![0; steps.len()];
    for (r, &i) in by_key.iter().enumerate() {
        rank[i] = r;
    }
    rank
}

/// Only edges inside one set constrain the order; one link per step pair.
fn pairs_within_sets<'e>(
    links: Vec<(usize, usize, &'e DataEdge)>,
    sets: &[StepSet],
) -> Vec<Pair<'e>> {
    let mut pair: HashMap<(usize, usize), usize> = HashMap::new();
    let mut pairs: Vec<Pair> = Vec::new();
    for (a, b, e) in links {
        if sets[a] != sets[b] {
            continue;
        }
        match pair.get(&(a, b)) {
            Some(&p) => pairs[p].inhibition &= e.into_inhibition,
            None => {
                pair.insert((a, b), pairs.len());
                pairs.push(Pair {
                    from: a,
                    to: b,
                    edge: e,
                    inhibition: e.into_inhibition,
                    broken: false,
                });
            }
        }
    }
    pairs
}

struct Pair<'e> {
    from: usize,
    to: usize,
    edge: &'e DataEdge,
    /// Every data edge of the pair ends at an inhibition input.
    inhibition: bool,
    broken: bool,
}

/// Flooding as in FINROC: from sense and control steps forward and backward through
/// update steps, stopping at the next sense or control step.
fn assign_sets(
    steps: &[(ElementId, StepKind)],
    links: &[(usize, usize, &DataEdge)],
) -> Vec<StepSet> {
    let n = steps.len();
    let mut succ = vec![Vec::new(); n];
    let mut pred = vec![Vec::new(); n];
    for &(a, b, _) in links {
        succ[a].push(b);
        pred[b].push(a);
    }
    let is_update = |i: usize| steps[i].1 == StepKind::Update;
    let mut flags = vec![0u8; n];
    let mut stack = Vec::new();
    for (seed_kind, forward, backward) in [
        (StepKind::Sense, SENSE_DEPENDENT, SENSE_DEPENDENCY),
        (StepKind::Control, CONTROL_DEPENDENT, CONTROL_DEPENDENCY),
    ] {
        for (adjacent, flag) in [(&succ, forward), (&pred, backward)] {
            stack.extend((0..n).filter(|&i| steps[i].1 == seed_kind));
            while let Some(i) = stack.pop() {
                for &j in &adjacent[i] {
                    if is_update(j) && flags[j] & flag == 0 {
                        flags[j] |= flag;
                        stack.push(j);
                    }
                }
            }
        }
    }
    (0..n)
        .map(|i| match steps[i].1 {
            StepKind::Sense => StepSet::Sense,
            StepKind::Control => StepSet::Control,
            StepKind::Update => classify(flags[i]),
        })
        .collect()
}

struct Order {
    sequence: Vec<usize>,
    /// Broken pair and the loop it closed (pairs in data-flow order, starting with the
    /// pair leaving the broken pair's target).
    broken: Vec<(usize, Vec<usize>)>,
}

/// Kahn's algorithm, smallest rank first; when every remaining step waits for another,
/// walk back from the smallest remaining step to find a loop and break one of its pairs.
fn topological(rank: &[usize], pairs: &mut [Pair<'_>]) -> Order {
    let n = rank.len();
    let mut succ: Vec<Vec<usize>> = vec![Vec::new(); n];
    let mut pred: Vec<Vec<usize>> = vec![Vec::new(); n];
    let mut waiting = vec![0usize; n];
    for (p, pr) in pairs.iter().enumerate() {
        succ[pr.from].push(p);
        pred[pr.to].push(p);
        waiting[pr.to] += 1;
    }
    let mut ready: BinaryHeap<Reverse<(usize, usize)>> = (0..n)
        .filter(|&i| waiting[i] == 0)
        .map(|i| Reverse((rank[i], i)))
        .collect();
    let mut remaining: BTreeSet<(usize, usize)> = (0..n).map(|i| (rank[i], i)).collect();
    let mut done = vec![false; n];
    let mut order = Order {
        sequence: Vec::with_capacity(n),
        broken: Vec::new(),
    };
    while !remaining.is_empty() {
        if let Some(Reverse((r, i))) = ready.pop() {
            remaining.remove(&(r, i));
            done[i] = true;
            order.sequence.push(i);
            for &p in &succ[i] {
                if pairs[p].broken {
                    continue;
                }
                let to = pairs[p].to;
                waiting[to] -= 1;
                if waiting[to] == 0 {
                    ready.push(Reverse((rank[to], to)));
                }
            }
            continue;
        }
        let Some(&(_, start)) = remaining.iter().next() else {
            break;
        };
        let cycle = find_loop(start, rank, pairs, &pred, &done);
        if cycle.is_empty() {
            // Unreachable when the bookkeeping is right; never loop forever on it.
            ready.push(Reverse((rank[start], start)));
            continue;
        }
        let victim = choose_victim(&cycle, rank, pairs);
        pairs[victim].broken = true;
        let to = pairs[victim].to;
        waiting[to] -= 1;
        if waiting[to] == 0 {
            ready.push(Reverse((rank[to], to)));
        }
        // Rotate so the loop starts with the pair leaving the victim's target.
        let at = cycle.iter().position(|&p| p == victim).unwrap_or(0);
        let mut rotated: Vec<usize> = cycle[at + 1..].to_vec();
        rotated.extend_from_slice(&cycle[..=at]);
        order.broken.push((victim, rotated));
    }
    order
}

/// Walks back along live predecessors (smallest rank first) until a step repeats; returns
/// the loop as pairs in data-flow order.
fn find_loop(
    start: usize,
    rank: &[usize],
    pairs: &[Pair<'_>],
    pred: &[Vec<usize>],
    done: &[bool],
) -> Vec<usize> {
    let mut trace: Vec<(usize, usize)> = Vec::new(); // (step, pair entering it)
    let mut seen: HashMap<usize, usize> = HashMap::new();
    let mut current = start;
    loop {
        if let Some(&pos) = seen.get(&current) {
            // trace[pos..] walked backwards; reverse for data-flow order.
            let mut cycle: Vec<usize> = trace[pos..].iter().map(|(_, p)| *p).collect();
            cycle.reverse();
            return cycle;
        }
        seen.insert(current, trace.len());
        let Some(&p) = pred[current]
            .iter()
            .filter(|&&p| !pairs[p].broken && !done[pairs[p].from])
            .min_by_key(|&&p| rank[pairs[p].from])
        else {
            return Vec::new(); // cannot happen: a waiting step has a live predecessor
        };
        trace.push((current, p));
        current = pairs[p].from;
    }
}

/// The pair to ignore: among the loop's inhibition inputs if it has any (mutual
/// inhibition is normal in iB2C), otherwise among all its pairs, the one into the
/// smallest-ranked step, which then runs first.
fn choose_victim(cycle: &[usize], rank: &[usize], pairs: &[Pair<'_>]) -> usize {
    let inhibition = cycle.iter().any(|&p| pairs[p].inhibition);
    cycle
        .iter()
        .copied()
        .filter(|&p| !inhibition || pairs[p].inhibition)
        .min_by_key(|&p| rank[pairs[p].to])
        .unwrap_or(cycle[0])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn classification_follows_the_flags() {
        assert_eq!(classify(0), StepSet::Other);
        assert_eq!(
            classify(SENSE_DEPENDENCY | CONTROL_DEPENDENCY),
            StepSet::Initial
        );
        assert_eq!(
            classify(SENSE_DEPENDENT | CONTROL_DEPENDENCY),
            StepSet::Sense
        );
        assert_eq!(
            classify(CONTROL_DEPENDENT | SENSE_DEPENDENCY),
            StepSet::Sense
        );
        assert_eq!(classify(CONTROL_DEPENDENT), StepSet::Control);
    }
}
