//! The compiler's plan as a run plan (`ferroc_runner::plan`): what a runner is handed,
//! and, piece by piece, what structural edits (`edit.rs`) and the bundle take from it.
//! The runtime's view of each piece is `ferroc_runner::from_plan`'s, the one
//! implementation.

use ferroc_compiler::ir::Application;
use ferroc_compiler::library::PortDir;
use ferroc_compiler::plan::{self, Plan};
use ferroc_compiler::schedule::StepKind;
use ferroc_inspect::param_value::runtime_value;
use ferroc_runner::plan as run;
use ferroc_runtime::container::ThreadOptions;
use ferroc_runtime::module::Direction;

/// The run plan of `plan` (of the checked `app`), with `app`'s name and seed, and
/// default run options (the caller sets them).
pub fn run_plan(plan: &Plan, app: &Application) -> run::RunPlan {
    let mut out = run::RunPlan::new(&app.name);
    out.seed = app.seed;
    out.modules = (plan.modules.iter())
        .map(|m| {
            let part = app.element(m.element).part;
            module(m, part.map(|p| app.element(p).name.clone()))
        })
        .collect();
    out.connections = plan.connections.iter().map(connection).collect();
    out.calls = (plan.calls.iter())
        .map(|c| run::Call {
            client: c.client.clone(),
            service: c.service.clone(),
            link: c.link.as_ref().map(|l| run::CallLink {
                id: l.id,
                client_part: l.client_part.clone(),
                server_part: l.server_part.clone(),
            }),
        })
        .collect();
    out.param_links = (plan.param_links.iter())
        .map(|l| run::ParamLink {
            from: l.from.clone(),
            to: l.to.clone(),
            scale: l.scale,
            link: l.link.as_ref().map(link),
        })
        .collect();
    out.threads = plan.threads.iter().map(thread).collect();
    out.locks = run::Locks {
        resources: plan.locks.resources.clone(),
        binds: plan.locks.binds.clone(),
        orders: plan.locks.orders.clone(),
    };
    out.units = plan.units.clone();
    out.ros2 = plan.ros2.clone();
    out
}

/// A planned module, in the part `part`.
pub fn module(m: &plan::PlannedModule, part: Option<String>) -> run::Module {
    run::Module {
        path: m.path.clone(),
        type_name: m.type_name.clone(),
        part,
        params: (m.params.iter())
            .map(|(n, v)| (n.clone(), runtime_value(v)))
            .collect(),
        queues: m.queues.clone(),
        ports: (m.ports.iter())
            .map(|g| run::PortGroup {
                name: g.name.clone(),
                dir: match g.dir {
                    PortDir::In => Direction::In,
                    PortDir::Out => Direction::Out,
                },
                ty: g.ty.clone(),
                count: g.count,
            })
            .collect(),
        ib2c_violations: m.ib2c_violations.clone(),
    }
}

fn connection(c: &plan::PlannedConnection) -> run::Connection {
    run::Connection {
        from: c.from.clone(),
        to: c.to.clone(),
        select: (c.select.iter())
            .map(|p| match p {
                plan::Part::Field(f) => run::Part::Field(f.clone()),
                plan::Part::Index(i) => run::Part::Index(*i),
            })
            .collect(),
        scale: c.scale,
        offset: c.offset,
        link: c.link.as_ref().map(link),
        local: c.local,
    }
}

/// A planned link between parts.
pub fn link(l: &plan::PlannedLink) -> run::Link {
    run::Link {
        id: l.id,
        from_part: l.from_part.clone(),
        to_part: l.to_part.clone(),
        ty: l.ty.clone(),
        sharing: match l.sharing {
            plan::LinkSharing::OnChange { min_interval } => {
                run::LinkSharing::OnChange { min_interval }
            }
            plan::LinkSharing::Periodic { period } => run::LinkSharing::Periodic { period },
        },
        reliable: l.reliable,
        deadline: l.deadline,
    }
}

/// A planned thread container.
pub fn thread(t: &plan::PlannedThread) -> run::Thread {
    run::Thread {
        path: t.path.clone(),
        period: t.period,
        continuous: t.continuous,
        wait: match t.wait {
            plan::Wait::Park => run::Wait::Park,
            plan::Wait::Spin => run::Wait::Spin,
            plan::Wait::Adaptive => run::Wait::Adaptive,
            plan::Wait::Inline => run::Wait::Inline,
        },
        priority: t.priority,
        cpu: t.cpu,
        steps: (t.steps.iter())
            .map(|(p, k)| (p.clone(), step(k)))
            .collect(),
    }
}

/// A planned step.
pub fn step(kind: &StepKind) -> run::Step {
    match kind {
        StepKind::Update => run::Step::Update,
        StepKind::Sense => run::Step::Sense,
        StepKind::Control => run::Step::Control,
    }
}

/// Priority, CPU and waiting of a planned thread, as the runtime takes them.
pub fn thread_options(t: &plan::PlannedThread) -> ThreadOptions {
    ferroc_runner::from_plan::thread_options(&thread(t))
}
