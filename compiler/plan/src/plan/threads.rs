//! The thread containers (timing and the scheduling pass's step order) and the locks
//! the runtime validates acquisitions against: the parts of the plan about what runs
//! where, taken from the model after the modules and connections are planned.

use super::{PlannedLocks, PlannedThread};
use ferroc_model::ir::{Application, ElementKind};
use ferroc_model::library::LibrarySet;
use ferroc_schedule as schedule;

/// Each thread container with its timing and the step order of the scheduling pass.
pub(super) fn plan_threads(
    app: &Application,
    libs: &LibrarySet,
    paths: &[String],
) -> Vec<PlannedThread> {
    let mut threads = Vec::new();
    for container in schedule::compute(app, libs).containers {
        let ElementKind::Thread {
            period,
            continuous,
            wait,
            ..
        } = app.element(container.thread).kind
        else {
            continue;
        };
        threads.push(PlannedThread {
            path: app.path(container.thread),
            period,
            continuous,
            wait,
            priority: app.timing.priority.get(&container.thread).map(|(p, _)| *p),
            cpu: app.timing.cpu.get(&container.thread).map(|(c, _)| *c),
            steps: container
                .steps
                .iter()
                .map(|s| (paths[s.module.0 as usize].clone(), s.kind))
                .collect(),
        });
    }
    threads
}

/// The application's resources, the modules' lock-slot bindings and the nesting
/// orders their types declare, in resource names.
pub(super) fn plan_locks(app: &Application, libs: &LibrarySet, paths: &[String]) -> PlannedLocks {
    let mut locks = PlannedLocks {
        resources: app
            .resources
            .iter()
            .map(|r| (r.name.clone(), r.level, r.recursive))
            .collect(),
        ..PlannedLocks::default()
    };
    let mut declared = std::collections::HashSet::new();
    for (id, m) in app.modules() {
        let ty = &libs.get(m.library).module_types[m.type_index];
        let path = &paths[id.0 as usize];
        for (slot, resource, _) in m.binds() {
            locks
                .binds
                .push((path.clone(), slot.clone(), resource.clone()));
        }
        let resource_of = |slot: &String| {
            m.binds()
                .iter()
                .find(|(s, _, _)| s == slot)
                .map_or(slot.clone(), |(_, r, _)| r.clone())
        };
        for sequence in &ty.lock_orders {
            for pair in sequence.windows(2) {
                let (a, b) = (resource_of(&pair[0]), resource_of(&pair[1]));
                if a != b && declared.insert((a.clone(), b.clone())) {
                    let why = format!(
                        "<locks order=\"{}\"> of `{}`, as bound in `{path}`",
                        sequence.join(" "),
                        ty.qualified
                    );
                    locks.orders.push((a, b, why));
                }
            }
        }
    }
    locks
}
