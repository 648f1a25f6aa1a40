//! The warehouse AGV fleet (manifest: `components/warehouse.lib.xml`), simulated.
//!
//! Every module type of the manifest is implemented. Hardware is simulated so that a
//! model runs anywhere and prints the same thing for the same number of cycles: no wall
//! clock and no randomness — time advances by the nominal period of the thread container
//! each module is meant for in `models/warehouse_fleet.xml` (see [`timing`]), and the
//! few "random" things (orders, people crossing an aisle) come from a fixed-seed
//! generator keyed by a parameter.
//!
//! - drive: [`DiffDriveKinematics`] (wheel odometry, body velocity → wheel speeds) and
//!   [`WheelMotor`] (a CANopen velocity-mode motor with a current limit);
//! - safety, power, load: [`SafetyScanner`] (an aisle seen from the robot, with people
//!   crossing now and then), [`BatteryMonitor`], [`Lift`];
//! - iB2C: [`FollowPath`], [`AvoidObstacles`], [`VelocityFusion`];
//! - tasks: [`TaskExecutor`] (per robot), [`WmsBridge`] (order intake),
//!   [`FleetManager`] (dispatch), [`FleetDashboard`] (status line).

#![forbid(unsafe_code)]

mod behaviours;
mod dashboard;
mod dispatch;
mod drive;
mod executor;
mod fleet;
mod geometry;
mod lift;
mod motor;
mod orders;
mod power;
mod scanner;
mod sequence;
pub mod timing;

pub use behaviours::{AvoidObstacles, FollowPath, VelocityFusion};
pub use dashboard::{FleetDashboard, Rotation};
pub use dispatch::{Dispatcher, Round, Strategy};
pub use drive::{Chassis, DiffDriveKinematics};
pub use executor::{Mission, Phase, TaskExecutor};
pub use fleet::FleetManager;
pub use geometry::{wrap, PurePursuit};
pub use lift::{Lift, LiftMotion, LiftState};
pub use motor::{MotorModel, WheelMotor};
pub use orders::{OrderGenerator, WmsBridge};
pub use power::{BatteryModel, BatteryMonitor};
pub use scanner::{AisleScene, SafetyScanner};

pub use rescue_components::{LaserScan, Pose2D};

use ferroc_runtime::builder::Registry;
use serde::{Deserialize, Serialize};
use std::time::Duration;

/// A transport order: fetch the shelf at `pickup` and bring it to `dropoff`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Task {
    /// Unique per order source; 0 means "no task".
    pub id: u64,
    pub pickup: Pose2D,
    pub dropoff: Pose2D,
    /// Higher is more urgent.
    pub priority: u8,
    /// When the shelf should be at the drop-off (model time since the start).
    pub deadline: Duration,
}

ferroc_runtime::port_value!(Task, "warehouse.Task", pooled);

/// What an AGV reports to the fleet manager.
///
/// Copy type on the seqlock path: `#[repr(C)]` with the fields ordered by alignment and
/// the tail padding made an explicit field, so that `NoUninit` holds (no padding bytes).
/// The manifest's field order is the model's business; serde names the fields.
#[derive(Clone, Copy, Default, PartialEq, bytemuck::NoUninit, Serialize, Deserialize)]
#[repr(C)]
pub struct RobotStatus {
    pub pose: Pose2D,
    /// The current task, or the last one when `busy` is false (0: none yet).
    pub task_id: u64,
    pub robot_id: u32,
    /// Tasks completed since start.
    pub tasks_done: u32,
    /// State of charge, 0 .. 1.
    pub battery_charge: f32,
    /// Working on `task_id` (or driving to charge).
    pub busy: bool,
    /// Explicit tail padding (always zero).
    #[serde(skip)]
    pub reserved: [u8; 3],
}

ferroc_runtime::port_value!(RobotStatus, "warehouse.RobotStatus", copy);

/// The manifest's fields in its order, without the padding (what `Dump` and `Logger`
/// print).
impl std::fmt::Debug for RobotStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RobotStatus")
            .field("robot_id", &self.robot_id)
            .field("pose", &self.pose)
            .field("battery_charge", &self.battery_charge)
            .field("busy", &self.busy)
            .field("task_id", &self.task_id)
            .field("tasks_done", &self.tasks_done)
            .finish()
    }
}

/// Registers every module type of this library.
pub fn register(registry: &mut Registry) {
    registry
        .register::<DiffDriveKinematics>()
        .register::<WheelMotor>()
        .register::<SafetyScanner>()
        .register::<BatteryMonitor>()
        .register::<Lift>()
        .register_behaviour::<FollowPath>()
        .register_behaviour::<AvoidObstacles>()
        .register_behaviour::<VelocityFusion>()
        .register::<TaskExecutor>()
        .register::<WmsBridge>()
        .register::<FleetManager>()
        .register::<FleetDashboard>();
    register_fields(registry);
    register_values(registry);
}

/// The value types flexible modules may make ports of (`ferroc_std.FlexiSelect`,
/// `Logger` and `Dump` of robot status and tasks; `warehouse_fleet.xml` also logs the
/// rescue library's poses, registered here too: registering a type twice is harmless).
fn register_values(registry: &mut Registry) {
    registry
        .register_serde::<RobotStatus>()
        .register_serde::<Task>()
        .register_serde::<Pose2D>()
        .register_serde::<LaserScan>();
}

/// Field accessors for `<convert field="…"/>` on connections carrying a robot status
/// or a task (`warehouse_fleet.xml` sums the robots' `tasks_done`). Called by
/// [`register`]; public for binaries that register module types one by one.
pub fn register_fields(registry: &mut Registry) {
    registry
        .register_field::<RobotStatus, u32>("robot_id", |s| s.robot_id)
        .register_field::<RobotStatus, Pose2D>("pose", |s| s.pose)
        .register_field::<RobotStatus, f32>("battery_charge", |s| s.battery_charge)
        .register_field::<RobotStatus, bool>("busy", |s| s.busy)
        .register_field::<RobotStatus, u64>("task_id", |s| s.task_id)
        .register_field::<RobotStatus, u32>("tasks_done", |s| s.tasks_done)
        .register_field::<Task, u64>("id", |t| t.id)
        .register_field::<Task, Pose2D>("pickup", |t| t.pickup)
        .register_field::<Task, Pose2D>("dropoff", |t| t.dropoff)
        .register_field::<Task, u8>("priority", |t| t.priority);
}

#[cfg(test)]
mod tests {
    use super::*;
    use ferroc_runtime::module::PortValue;

    #[test]
    fn status_is_padding_free_and_named() {
        // NoUninit is checked by the derive at compile time; the size shows the layout.
        assert_eq!(
            std::mem::size_of::<RobotStatus>(),
            24 + 8 + 4 + 4 + 4 + 1 + 3
        );
        assert_eq!(RobotStatus::model_type(), "warehouse.RobotStatus");
        assert_eq!(Task::model_type(), "warehouse.Task");
    }

    #[test]
    fn status_serialises_with_the_manifest_field_names() {
        let status = RobotStatus {
            robot_id: 2,
            tasks_done: 5,
            busy: true,
            ..RobotStatus::default()
        };
        let json = serde_json::to_value(status).unwrap();
        for field in [
            "robot_id",
            "pose",
            "battery_charge",
            "busy",
            "task_id",
            "tasks_done",
        ] {
            assert!(json.get(field).is_some(), "{field} missing in {json}");
        }
        assert!(json.get("reserved").is_none());
        let back: RobotStatus = serde_json::from_value(json).unwrap();
        assert_eq!(back, status);
        let text = format!("{status:?}");
        assert!(
            text.starts_with("RobotStatus { robot_id: 2, pose: "),
            "{text}"
        );
        assert!(
            text.ends_with("tasks_done: 5 }") && !text.contains("reserved"),
            "{text}"
        );
    }
}
