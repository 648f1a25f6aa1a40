//! `warehouse.FleetDashboard`: the fleet at a glance, as one status line per second.
//!
//! The web server of the real dashboard is not simulated (a module's creation must be
//! free of side effects, and a test run should not open ports); the status line shows
//! what its overview page would.

use crate::timing::MONITOR_STEP;
use crate::RobotStatus;
use ferroc_runtime::console;
use ferroc_runtime::module::{In, Module, ModuleType, Out, Parameter, Setup};

/// Cycles between two status lines: one second at the monitoring period.
const PRINT_EVERY: u64 = (1.0 / MONITOR_STEP) as u64;
/// Cycles the detail view stays on one robot: ten seconds.
const DWELL: u32 = (10.0 / MONITOR_STEP) as u32;
/// Most robots the detail view rotates through.
const MAX_ROBOTS: usize = 64;

/// The detail view's rotation through the robots. The dashboard does not know how many
/// robots there are: it moves on to the next index every [`DWELL`] cycles and starts
/// over when an index shows no robot, or one already shown at a lower index.
#[derive(Clone, Debug, Default)]
pub struct Rotation {
    index: u32,
    cycles: u32,
    /// Robot id shown at each index so far.
    seen: Vec<u32>,
}

impl Rotation {
    /// One cycle, with the status shown now; returns the index to select.
    pub fn step(&mut self, shown: &RobotStatus) -> u32 {
        self.cycles += 1;
        if self.cycles < DWELL {
            return self.index;
        }
        self.cycles = 0;
        let k = self.index as usize;
        let repeated = self.seen.iter().take(k).any(|&id| id == shown.robot_id);
        if shown.robot_id == 0 || repeated || k + 1 >= MAX_ROBOTS {
            self.index = 0;
        } else {
            if self.seen.len() <= k {
                self.seen.resize(k + 1, 0);
            }
            self.seen[k] = shown.robot_id;
            self.index += 1;
        }
        self.index
    }
}

/// One compact status line.
pub fn status_line(
    title: &str,
    seconds: f64,
    total: u32,
    throughput: f64,
    pending: u32,
    robot: &RobotStatus,
) -> String {
    let detail = if robot.robot_id == 0 {
        "robot -".to_string()
    } else {
        format!(
            "robot {}: {} task {} at ({:+.1}, {:+.1}) battery {:.0}% done {}",
            robot.robot_id,
            if robot.busy { "busy" } else { "idle" },
            robot.task_id,
            robot.pose.x,
            robot.pose.y,
            f64::from(robot.battery_charge) * 100.0,
            robot.tasks_done
        )
    };
    format!(
        "[{title}] t={seconds:.0} s | tasks {total} ({throughput:.2}/h) | pending {pending} | {detail}"
    )
}

/// Prints the fleet's state once a second and rotates the detail view.
pub struct FleetDashboard {
    selected_status: In<RobotStatus>,
    throughput: In<f64>,
    total_tasks: In<u32>,
    pending_orders: In<u32>,
    selected_robot: Out<u32>,
    http_port: Parameter<u16>,
    title: Parameter<String>,
    rotation: Rotation,
    cycle: u64,
}

impl ModuleType for FleetDashboard {
    const NAME: &'static str = "warehouse.FleetDashboard";
    const DOC: &'static str = "Web dashboard of the fleet";

    fn create(m: &mut Setup<'_>) -> Self {
        FleetDashboard {
            selected_status: m.input("selected_status").build(),
            throughput: m.input("throughput").doc("tasks per hour").build(),
            total_tasks: m.input("total_tasks").build(),
            pending_orders: m.input("pending_orders").build(),
            selected_robot: m
                .output("selected_robot")
                .doc("index of the robot shown in the detail view")
                .build(),
            http_port: m
                .param("http_port")
                .range(1.0, 65535.0)
                .default(8080)
                .build(),
            title: m.param("title").default("fleet".to_string()).build(),
            rotation: Rotation::default(),
            cycle: 0,
        }
    }
}

impl Module for FleetDashboard {
    fn update(&mut self) {
        let shown = self.selected_status.get();
        if self.cycle == 0 {
            let port = self.http_port.get();
            console::line(&format!(
                "[{}] dashboard (simulated; the web view would be on port {port})",
                self.title.value()
            ));
        }
        if self.cycle % PRINT_EVERY == 0 {
            let line = status_line(
                self.title.value(),
                self.cycle as f64 * MONITOR_STEP,
                self.total_tasks.get(),
                self.throughput.get(),
                self.pending_orders.get(),
                &shown,
            );
            console::line(&line);
        }
        self.cycle += 1;
        self.selected_robot.publish(self.rotation.step(&shown));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn robot(id: u32) -> RobotStatus {
        RobotStatus {
            robot_id: id,
            ..RobotStatus::default()
        }
    }

    /// Runs the rotation over a fleet of `n` robots (index k shows robot k+1; beyond
    /// the fleet, nothing) and returns the sequence of indices at each dwell's end.
    fn indices(n: u32, dwells: usize) -> Vec<u32> {
        let mut r = Rotation::default();
        let mut selected = 0;
        let mut out = Vec::new();
        for _ in 0..dwells {
            for _ in 0..DWELL {
                let shown = if selected < n {
                    robot(selected + 1)
                } else {
                    robot(0)
                };
                selected = r.step(&shown);
            }
            out.push(selected);
        }
        out
    }

    #[test]
    fn the_detail_view_rotates_through_the_fleet() {
        assert_eq!(indices(3, 8), [1, 2, 3, 0, 1, 2, 3, 0]);
        assert_eq!(indices(1, 4), [1, 0, 1, 0]);
        // A selector that repeats its last input for higher indices.
        let mut r = Rotation::default();
        let mut selected = 0;
        let mut picked = Vec::new();
        for _ in 0..6 * DWELL {
            selected = r.step(&robot(selected.min(1) + 1));
            picked.push(selected);
        }
        assert!(picked.iter().all(|&k| k <= 2), "{picked:?}");
    }

    #[test]
    fn the_status_line_is_compact() {
        let busy = RobotStatus {
            robot_id: 2,
            busy: true,
            task_id: 7,
            tasks_done: 3,
            battery_charge: 0.5,
            pose: crate::Pose2D {
                x: 4.0,
                y: -1.25,
                theta: 0.0,
            },
            ..RobotStatus::default()
        };
        assert_eq!(
            status_line("fleet", 12.0, 5, 0.625, 4, &busy),
            "[fleet] t=12 s | tasks 5 (0.62/h) | pending 4 | robot 2: busy task 7 at (+4.0, -1.2) battery 50% done 3"
        );
        assert!(status_line("fleet", 0.0, 0, 0.0, 0, &robot(0)).ends_with("| robot -"));
    }
}
