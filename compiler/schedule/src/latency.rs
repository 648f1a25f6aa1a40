//! End-to-end latency bounds along data edges (`docs/model-language.md`: `<flow>`;
//! `reference/deadlocks.md` §1(f)), for `<flow>` requirements (checks S105, S106).
//!
//! Time is measured from the start of the flow's first module to the completion of its
//! last. A node is one step of a module; the cost of reaching a step is the worst-case
//! time until that step has completed. Each module's budget is counted in full at each of
//! its steps (a sense-control module may do all its work in either step). A data edge
//! from step `a` to step `b` costs:
//!
//! - same container, `b` after `a` in the schedule: the budgets of the steps after `a`
//!   up to and including `b` (no extra cycle);
//! - same container, against the schedule (a broken loop edge, `delay="1"`, an edge into
//!   an earlier set): one period (`b` completes in the next cycle, before `a`'s point);
//! - another container: one reader period (the value may have just missed the read) plus
//!   the budgets of the reader's steps up to `b`;
//! - through a queue of capacity n: n − 1 more reader periods (items ahead of it).
//!
//! A data-triggered container's "period" is the sum of its budgets (it may be busy with
//! one activation when data arrives). The bound of a flow is the cheapest path (Dijkstra;
//! all costs are non-negative): the time within which `from`'s effect is guaranteed to
//! reach `to`. Loops are never taken twice. Network delays between parts are not known and
//! not counted.

use super::{data_edges, step_of, DataEdge, Schedule, StepKind};
use ferroc_model::ir::{Application, ElementId, ElementKind, Flow};
use ferroc_model::library::{LibrarySet, ModuleKind};
use hashbrown::HashMap;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// How one hop of a flow adds to its latency.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum HopKind {
    /// Inside one container, in schedule order.
    InOrder,
    /// Inside one container, against schedule order: one period.
    AgainstOrder { period: f64 },
    /// From one container to another: one reader period.
    Sampled { period: f64 },
    /// Inside a module: from its sense step to its control step (same cycle).
    SenseToControl,
    /// Inside a module: from its control step to the next cycle's sense step.
    ControlToSense { period: f64 },
}

/// One hop of a flow's path.
#[derive(Debug, Clone)]
pub struct Hop {
    pub from: ElementId,
    pub to: ElementId,
    pub kind: HopKind,
    /// Queue capacity on the way (adds capacity − 1 periods), if any.
    pub queue: Option<u32>,
    /// Waiting for the reader (periods).
    pub wait: f64,
    /// Execution (budgets) until the receiving step completes.
    pub exec: f64,
    /// The data edge behind it (`None` inside a module).
    pub edge: Option<DataEdge>,
}

/// The bound of one flow: the first module's budget plus the hops.
#[derive(Debug, Clone)]
pub struct FlowBound {
    pub start: f64,
    pub hops: Vec<Hop>,
    pub total: f64,
}

/// A step of a module: the node of the latency graph.
type Node = (ElementId, StepKind);

struct Slot {
    container: usize,
    position: usize,
}

/// Per-container data the costs need.
struct Container {
    /// Completion time of each step within a cycle (prefix sums of budgets).
    end: Vec<f64>,
    /// The period (or total budget for data-triggered containers).
    period: f64,
}

/// Everything needed to bound any number of flows of one application.
pub struct Latencies<'a> {
    app: &'a Application,
    libs: &'a LibrarySet,
    slots: HashMap<Node, Slot>,
    containers: Vec<Container>,
    /// Outgoing data edges per step.
    out: HashMap<Node, Vec<(Node, DataEdge)>>,
}

fn budget(app: &Application, libs: &LibrarySet, m: ElementId) -> f64 {
    app.budget(libs, m).map_or(0.0, |b| b.0)
}

fn has_sense(app: &Application, libs: &LibrarySet, m: ElementId) -> bool {
    app.module_type(libs, m)
        .is_some_and(|mt| mt.kind == ModuleKind::SenseControl)
}

impl<'a> Latencies<'a> {
    pub fn new(app: &'a Application, libs: &'a LibrarySet, schedule: &Schedule) -> Self {
        let mut slots = HashMap::new();
        let mut containers = Vec::new();
        for (k, c) in schedule.containers.iter().enumerate() {
            let mut t = 0.0;
            let mut end = Vec::with_capacity(c.steps.len());
            for (i, s) in c.steps.iter().enumerate() {
                t += budget(app, libs, s.module);
                end.push(t);
                slots.insert(
                    (s.module, s.kind),
                    Slot {
                        container: k,
                        position: i,
                    },
                );
            }
            let period = match app.element(c.thread).kind {
                ElementKind::Thread {
                    period: Some(p), ..
                } => p,
                _ => t,
            };
            containers.push(Container { end, period });
        }
        let mut out: HashMap<_, Vec<_>> = HashMap::new();
        for e in data_edges(app, libs) {
            let a = (
                e.from_module,
                step_of(e.from_role, has_sense(app, libs, e.from_module)),
            );
            let b = (
                e.to_module,
                step_of(e.to_role, has_sense(app, libs, e.to_module)),
            );
            if slots.contains_key(&a) && slots.contains_key(&b) {
                out.entry(a).or_default().push((b, e));
            }
        }
        Latencies {
            app,
            libs,
            slots,
            containers,
            out,
        }
    }

    fn end(&self, s: &Slot) -> f64 {
        self.containers[s.container].end[s.position]
    }

    /// The hop over one data edge.
    fn hop(&self, a: Node, b: Node, e: &DataEdge) -> Hop {
        let (sa, sb) = (&self.slots[&a], &self.slots[&b]);
        let reader = &self.containers[sb.container];
        let queue = e
            .hops
            .iter()
            .filter_map(|&i| self.app.connections[i].queue)
            .max()
            .filter(|&q| q > 0);
        let extra = queue.map_or(0.0, |q| (q - 1) as f64 * reader.period);
        let (kind, wait, exec) = if sa.container != sb.container {
            let kind = HopKind::Sampled {
                period: reader.period,
            };
            (kind, reader.period, self.end(sb))
        } else if sb.position > sa.position && !e.delayed {
            (HopKind::InOrder, 0.0, self.end(sb) - self.end(sa))
        } else {
            // Completes in the next cycle, before the point where `a` completed.
            let kind = HopKind::AgainstOrder {
                period: reader.period,
            };
            (kind, reader.period, 0.0)
        };
        Hop {
            from: a.0,
            to: b.0,
            kind,
            queue,
            wait: wait + extra,
            exec,
            edge: Some(e.clone()),
        }
    }

    /// Hops inside a sense-control module between its two steps.
    fn internal(&self, a: Node) -> Option<(Node, Hop)> {
        let other = match a.1 {
            StepKind::Sense => StepKind::Control,
            StepKind::Control => StepKind::Sense,
            StepKind::Update => return None,
        };
        let b = (a.0, other);
        let (sa, sb) = (self.slots.get(&a)?, self.slots.get(&b)?);
        let period = self.containers[sb.container].period;
        let (kind, wait, exec) = if a.1 == StepKind::Sense && sb.position > sa.position {
            (HopKind::SenseToControl, 0.0, self.end(sb) - self.end(sa))
        } else {
            (HopKind::ControlToSense { period }, period, 0.0)
        };
        let hop = Hop {
            from: a.0,
            to: a.0,
            kind,
            queue: None,
            wait,
            exec,
            edge: None,
        };
        Some((b, hop))
    }

    /// The cheapest bound from `flow.from` to `flow.to`; `None` when no data path joins them.
    pub fn bound(&self, flow: &Flow) -> Option<FlowBound> {
        self.bound_between(flow.from, flow.to)
    }

    pub fn bound_between(&self, from: ElementId, to: ElementId) -> Option<FlowBound> {
        let start = budget(self.app, self.libs, from);
        let mut dist: HashMap<(ElementId, StepKind), f64> = HashMap::new();
        let mut prev: HashMap<(ElementId, StepKind), ((ElementId, StepKind), Hop)> = HashMap::new();
        let mut heap = BinaryHeap::new();
        for kind in [StepKind::Update, StepKind::Sense, StepKind::Control] {
            if self.slots.contains_key(&(from, kind)) {
                dist.insert((from, kind), start);
                heap.push(Entry(start, (from, kind)));
            }
        }
        let mut goal = None;
        while let Some(Entry(d, node)) = heap.pop() {
            if dist.get(&node).is_some_and(|&best| d > best) {
                continue;
            }
            if node.0 == to {
                goal = Some((d, node));
                break;
            }
            let mut next: Vec<(Node, Hop)> = self
                .out
                .get(&node)
                .into_iter()
                .flatten()
                .map(|(b, e)| (*b, self.hop(node, *b, e)))
                .collect();
            next.extend(self.internal(node));
            for (b, hop) in next {
                let nd = d + hop.wait + hop.exec;
                if dist.get(&b).is_none_or(|&old| nd < old) {
                    dist.insert(b, nd);
                    prev.insert(b, (node, hop));
                    heap.push(Entry(nd, b));
                }
            }
        }
        let (total, mut node) = goal?;
        let mut hops = Vec::new();
        while let Some((p, hop)) = prev.get(&node) {
            hops.push(hop.clone());
            node = *p;
        }
        hops.reverse();
        Some(FlowBound { start, hops, total })
    }
}

/// Min-heap entry ordered by cost, then by node (deterministic).
struct Entry(f64, Node);

impl PartialEq for Entry {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Entry {}
impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Entry {
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .0
            .total_cmp(&self.0)
            .then_with(|| other.1.cmp(&self.1))
    }
}
