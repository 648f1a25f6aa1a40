//! The static execution order of every thread container.
//!
//! FINROC computes this at run time and breaks ties by pointer order; ferroc computes it
//! once in the compiler, deterministically, and the runtime (and the bundle) execute
//! exactly this order. The rules, after FINROC's `tThreadContainerThread`
//! (`../shared/design/reference/finroc.md` §2.3):
//!
//! 1. Each module contributes steps: a sense-control module a `sense` and a `control`
//!    step, every other module one `update` step.
//! 2. Update steps are put in a set by what they are connected to inside the container
//!    (see [`order::classify`]): `initial` (feeds both sensing and control), `sense`,
//!    `control` or `other`. Sets run in that order.
//! 3. Inside a set, steps run in topological order along data edges. Edges leaving the
//!    container and edges between sets are not ordering constraints: an edge against the
//!    set order delivers the previous cycle's value by design (the sensor → controller
//!    → actuator → sensor loop).
//! 4. A loop inside a set is broken at one edge, which then delivers the previous cycle's
//!    value. Edges marked `delay="1"` are left out beforehand; a loop closed through an
//!    iB2C inhibition input is broken there (mutual inhibition is normal). Every other
//!    broken loop is reported by check S101.
//! 5. Ties are broken by element path, so the order is the same on every run.

#![forbid(unsafe_code)]

mod flow;
pub mod latency;
mod order;

pub use flow::{call_edges, data_edges, DataEdge};

use ferroc_model::ir::{Application, ElementId, ElementKind};
use ferroc_model::library::{LibrarySet, ModuleKind};

/// What a step of a module does in a cycle.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum StepKind {
    Update,
    Sense,
    Control,
}

impl StepKind {
    pub fn as_str(self) -> &'static str {
        match self {
            StepKind::Update => "update",
            StepKind::Sense => "sense",
            StepKind::Control => "control",
        }
    }
}

/// The sets of a container's schedule, in execution order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum StepSet {
    Initial,
    Sense,
    Control,
    Other,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Step {
    pub module: ElementId,
    pub kind: StepKind,
    pub set: StepSet,
}

/// An edge the scheduler ignored to break a loop: `to` runs before `from` and reads the
/// value `from` wrote in the previous cycle.
#[derive(Clone, Debug)]
pub struct BrokenEdge {
    pub from: Step,
    pub to: Step,
    /// The data edge behind it (its hops point at the `<connect>` elements).
    pub edge: DataEdge,
    /// The loop, in data-flow order, starting with `to`; each entry is a step and the
    /// data edge that leaves it towards the next entry.
    pub cycle: Vec<(Step, DataEdge)>,
    /// Broken at an iB2C inhibition input: expected, not reported.
    pub inhibition: bool,
}

/// The schedule of one thread container.
#[derive(Clone, Debug)]
pub struct ContainerSchedule {
    pub thread: ElementId,
    pub steps: Vec<Step>,
    pub broken: Vec<BrokenEdge>,
}

/// Schedules of all thread containers, in element order.
#[derive(Clone, Debug, Default)]
pub struct Schedule {
    pub containers: Vec<ContainerSchedule>,
}

/// Computes the schedule of every thread container of `app`.
pub fn compute(app: &Application, libs: &LibrarySet) -> Schedule {
    let edges = data_edges(app, libs);
    // Steps per container, in element order (the final order is decided by `order`).
    let mut per_thread: hashbrown::HashMap<ElementId, Vec<(ElementId, StepKind)>> =
        hashbrown::HashMap::new();
    let mut threads = Vec::new();
    for (i, element) in app.elements.iter().enumerate() {
        let id = ElementId(i as u32);
        match &element.kind {
            ElementKind::Thread { .. } => threads.push(id),
            ElementKind::Module(m) => {
                let Some(thread) = element.thread else {
                    continue; // not executed by any container: M112
                };
                let kinds: &[StepKind] = match libs.get(m.library).module_types[m.type_index].kind {
                    ModuleKind::SenseControl => &[StepKind::Sense, StepKind::Control],
                    _ => &[StepKind::Update],
                };
                let steps = per_thread.entry(thread).or_default();
                steps.extend(kinds.iter().map(|k| (id, *k)));
            }
            _ => {}
        }
    }
    let mut edges_per_thread: hashbrown::HashMap<ElementId, Vec<&DataEdge>> =
        hashbrown::HashMap::new();
    for edge in &edges {
        let from = app.element(edge.from_module).thread;
        if from.is_some() && from == app.element(edge.to_module).thread {
            if let Some(t) = from {
                edges_per_thread.entry(t).or_default().push(edge);
            }
        }
    }
    let containers = threads
        .into_iter()
        .map(|thread| {
            let steps = per_thread.remove(&thread).unwrap_or_default();
            let local = edges_per_thread.remove(&thread).unwrap_or_default();
            order::schedule_container(app, thread, steps, &local)
        })
        .collect();
    Schedule { containers }
}

/// The step of a module that a port with this role belongs to.
pub(crate) fn step_of(role: ferroc_model::library::PortRole, module_has_sense: bool) -> StepKind {
    use ferroc_model::library::PortRole;
    match (role, module_has_sense) {
        (_, false) => StepKind::Update,
        (PortRole::Sensor, true) => StepKind::Sense,
        (_, true) => StepKind::Control,
    }
}
