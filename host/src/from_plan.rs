//! A plan's pieces as the runtime's Builder takes them: values, modules' parameters,
//! queues and port groups, steps, thread settings, conversions and links. Shared by the
//! start of `ferroc run` (`build.rs`), by structural edits (`edit.rs`) and by the
//! bundle, which writes the same as source.

use ferroc_compiler::plan;
use ferroc_compiler::schedule::StepKind as PlanStep;
use ferroc_inspect::param_value::runtime_value;
use ferroc_runtime::builder::{Conversion, StepKind};
use ferroc_runtime::container::ThreadOptions;
use ferroc_runtime::link::{LinkSpec, Sharing};
use ferroc_runtime::module::{Direction, PortGroup, Value};
use ferroc_runtime::port::{OnFull, QueueConfig, WaitMode};
use std::time::Duration;

/// Priority and CPU of a planned thread. Model priorities are "higher runs first" like
/// SCHED_FIFO's, whose range is 1–99 on Linux; values beyond are clamped to it.
pub fn thread_options(t: &plan::PlannedThread) -> ThreadOptions {
    ThreadOptions {
        priority: t.priority.map(|p| p.clamp(1, 99) as i32),
        cpu: t.cpu.map(|c| c as usize),
        wait: match t.wait {
            plan::Wait::Park => WaitMode::Park,
            plan::Wait::Spin => WaitMode::Spin,
            plan::Wait::Adaptive => WaitMode::Adaptive,
        },
    }
}

/// What a planned connection does to values (the bundle writes the same as source).
pub fn conversion(c: &plan::PlannedConnection) -> Conversion {
    c.select.iter().fold(
        Conversion::linear(c.scale, c.offset),
        |conv, part| match part {
            plan::Part::Field(f) => conv.field(f),
            plan::Part::Index(i) => conv.index(*i as usize),
        },
    )
}

/// The runtime's description of a planned link.
pub fn link_spec(link: &plan::PlannedLink) -> LinkSpec<'_> {
    let seconds = |s: f64| Duration::from_secs_f64(s.clamp(0.0, 1e9));
    LinkSpec {
        id: link.id,
        from_part: &link.from_part,
        to_part: &link.to_part,
        model_type: &link.ty,
        sharing: match link.sharing {
            plan::LinkSharing::OnChange { min_interval } => Sharing::OnChange {
                min_interval: seconds(min_interval),
            },
            plan::LinkSharing::Periodic { period } => Sharing::Periodic(seconds(period)),
        },
        reliable: link.reliable,
        deadline: link.deadline.map(seconds),
    }
}

/// The parameter values of a planned module, as the runtime takes them.
pub fn params_of(m: &plan::PlannedModule) -> Vec<(String, Value)> {
    (m.params.iter())
        .map(|(n, v)| (n.clone(), runtime_value(v)))
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
