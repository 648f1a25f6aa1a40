//! A planned module and step as the runtime's Builder takes them (shared by the start
//! of `ferroc run` and by structural edits, `edit.rs`).

use crate::run::value;
use ferroc_compiler::plan;
use ferroc_compiler::schedule::StepKind as PlanStep;
use ferroc_runtime::builder::StepKind;
use ferroc_runtime::module::{Direction, PortGroup, Value};
use ferroc_runtime::port::{OnFull, QueueConfig};

/// The parameter values of a planned module, as the runtime takes them.
pub fn params_of(m: &plan::PlannedModule) -> Vec<(String, Value)> {
    (m.params.iter())
        .map(|(n, v)| (n.clone(), value(v)))
        .collect()
}

/// The input queues of a planned module.
pub fn queues_of(m: &plan::PlannedModule) -> Vec<(String, QueueConfig)> {
    (m.queues.iter())
        .map(|(port, n, policy)| {
            let on_full = match policy.as_str() {
                "drop-oldest" => OnFull::DropOldest,
                "drop-newest" => OnFull::DropNewest,
                _ => OnFull::Block,
            };
            (port.clone(), QueueConfig::new(*n as usize).on_full(on_full))
        })
        .collect()
}

/// The flexible port groups of a planned module.
pub fn ports_of(m: &plan::PlannedModule) -> Vec<PortGroup<'_>> {
    (m.ports.iter())
        .map(|g| {
            let dir = match g.dir {
                ferroc_compiler::library::PortDir::In => Direction::In,
                ferroc_compiler::library::PortDir::Out => Direction::Out,
            };
            PortGroup::new(&g.name, dir, &g.ty, g.count)
        })
        .collect()
}

/// The runtime's step kind of a planned step.
pub fn step_kind(kind: &PlanStep) -> StepKind {
    match kind {
        PlanStep::Update => StepKind::Update,
        PlanStep::Sense => StepKind::Sense,
        PlanStep::Control => StepKind::Control,
    }
}
