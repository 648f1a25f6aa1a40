//! A run plan's pieces as the runtime's Builder takes them: modules' parameters,
//! queues and port groups, steps, thread settings, conversions and links. Shared by
//! the start of a run (`build.rs`), by structural edits (`ferroc_host::edit`) and by
//! the bundle, which writes the same as source.

use crate::plan;
use ferroc_runtime::builder::{Conversion, StepKind};
use ferroc_runtime::container::ThreadOptions;
use ferroc_runtime::link::{LinkSpec, Sharing};
use ferroc_runtime::module::PortGroup;
use ferroc_runtime::port::{OnFull, QueueConfig, WaitMode};
use std::time::Duration;

/// Priority and CPU of a planned thread. Model priorities are "higher runs first" like
/// SCHED_FIFO's, whose range is 1–99 on Linux; values beyond are clamped to it.
pub fn thread_options(t: &plan::Thread) -> ThreadOptions {
    ThreadOptions {
        priority: t.priority.map(|p| p.clamp(1, 99) as i32),
        cpu: t.cpu.map(|c| c as usize),
        wait: match t.wait {
            plan::Wait::Park => WaitMode::Park,
            plan::Wait::Spin => WaitMode::Spin,
            plan::Wait::Adaptive => WaitMode::Adaptive,
            plan::Wait::Inline => WaitMode::Inline,
        },
    }
}

/// What a planned connection does to values (the bundle writes the same as source).
pub fn conversion(c: &plan::Connection) -> Conversion {
    c.select.iter().fold(
        Conversion::linear(c.scale, c.offset),
        |conv, part| match part {
            plan::Part::Field(f) => conv.field(f),
            plan::Part::Index(i) => conv.index(*i as usize),
        },
    )
}

/// The runtime's description of a planned link.
pub fn link_spec(link: &plan::Link) -> LinkSpec<'_> {
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

/// The input queues of a planned module.
pub fn queues_of(m: &plan::Module) -> Vec<(String, QueueConfig)> {
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
pub fn ports_of(m: &plan::Module) -> Vec<PortGroup<'_>> {
    (m.ports.iter())
        .map(|g| PortGroup::new(&g.name, g.dir, &g.ty, g.count))
        .collect()
}

/// The runtime's step kind of a planned step.
pub fn step_kind(kind: plan::Step) -> StepKind {
    match kind {
        plan::Step::Update => StepKind::Update,
        plan::Step::Sense => StepKind::Sense,
        plan::Step::Control => StepKind::Control,
    }
}
