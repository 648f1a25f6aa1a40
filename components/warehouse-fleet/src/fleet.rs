//! `warehouse.FleetManager`: one status input and one task output per robot (declared
//! by the instance), orders in, tasks out.

use crate::dispatch::{Dispatcher, Strategy};
use crate::timing::DISPATCH_STEP;
use crate::{RobotStatus, Task};
use ferroc_runtime::console;
use ferroc_runtime::module::{In, Module, ModuleType, Out, Parameter, Setup};
use std::time::Duration;

/// The instance's robot ports: `status/k` in, `task/k` out (none while the registry
/// learns the interface).
fn robot_ports(m: &mut Setup<'_>) -> (Vec<In<RobotStatus>>, Vec<Out<Task>>) {
    let statuses = m
        .flexible_inputs("status")
        .same_type()
        .min_count(1)
        .max_count(64)
        .build();
    let tasks = m
        .flexible_outputs("task")
        .same_type()
        .min_count(1)
        .max_count(64)
        .build_outputs();
    if statuses.len() != tasks.len() && !m.path().is_empty() {
        m.problem(format!(
            "{} status inputs but {} task outputs: declare one of each per robot",
            statuses.len(),
            tasks.len()
        ));
    }
    (statuses, tasks)
}

/// Assigns the WMS orders to the robots, one task per free robot at a time.
pub struct FleetManager {
    statuses: Vec<In<RobotStatus>>,
    tasks: Vec<Out<Task>>,
    orders: In<Task>,
    pending_orders: Out<u32>,
    strategy: Parameter<String>,
    reassign_after: Parameter<Duration>,
    dispatcher: Dispatcher,
    refused: u64,
}

impl ModuleType for FleetManager {
    const NAME: &'static str = "warehouse.FleetManager";
    const DOC: &'static str = "Assigns orders to robots";

    fn create(m: &mut Setup<'_>) -> Self {
        let (statuses, tasks) = robot_ports(m);
        let robots = statuses.len().min(tasks.len());
        FleetManager {
            statuses,
            tasks,
            orders: m.input("orders").doc("connect through a queue").build(),
            pending_orders: m.output("pending_orders").build(),
            strategy: m
                .param("strategy")
                .choices(&["nearest", "round_robin", "auction"])
                .default("nearest".to_string())
                .build(),
            reassign_after: m
                .param("reassign_after")
                .range(1.0, 3600.0)
                .default(Duration::from_secs(120))
                .build(),
            dispatcher: Dispatcher::new(robots),
            refused: 0,
        }
    }
}

impl Module for FleetManager {
    fn update(&mut self) {
        while let Some(order) = self.orders.try_pop() {
            if !self.dispatcher.add_order(Task::clone(&order)) {
                self.refused += 1;
                if self.refused == 1 {
                    console::line(&format!(
                        "[fleet] order {} refused: {} orders are waiting already",
                        order.id,
                        self.dispatcher.pending()
                    ));
                }
            }
        }
        for (k, status) in self.statuses.iter().enumerate() {
            if status.changed() {
                self.dispatcher.report(k, status.get());
            }
        }
        let strategy = Strategy::parse(self.strategy.value()).unwrap_or_default();
        let after = (self.reassign_after.get().as_secs_f64() / DISPATCH_STEP).ceil() as u64;
        let round = self.dispatcher.dispatch(strategy, after.max(1));
        for (robot, id) in round.taken_back {
            console::line(&format!(
                "[fleet] task {id} taken back from robot {robot}: no answer in {:?}",
                self.reassign_after.get()
            ));
        }
        for (robot, task) in round.sent {
            if let Some(out) = self.tasks.get(robot) {
                out.publish(task);
            }
        }
        let pending = u32::try_from(self.dispatcher.pending()).unwrap_or(u32::MAX);
        self.pending_orders.publish(pending);
    }
}
