//! The plan's values, thread settings, conversions and links as the runtime's Builder
//! takes them (the bundle writes the same conversions as source).

use ferroc_compiler::plan;
use ferroc_compiler::values::Value as ModelValue;
use ferroc_runtime::builder::Conversion;
use ferroc_runtime::container::ThreadOptions;
use ferroc_runtime::link::{LinkSpec, Sharing};
use ferroc_runtime::module::Value;
use ferroc_runtime::port::WaitMode;
use std::time::Duration;

/// A plan's parameter value as modules receive it: the conversion parameter changes
/// while running take too (`ferroc_inspect::param_value`).
pub(crate) fn value(v: &ModelValue) -> Value {
    ferroc_inspect::param_value::runtime_value(v)
}

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
pub(super) fn conversion(c: &plan::PlannedConnection) -> Conversion {
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
