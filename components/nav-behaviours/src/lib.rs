//! iB2C navigation behaviours (manifest: `components/nav_behaviours.lib.xml`) and the
//! arena simulation the demo `models/nav_behaviours.xml` runs them in.
//!
//! Implemented: `GoToGoal`, `AvoidObstacles`, `FollowWall` (behaviours),
//! `VelocityFusion` (fusion of (linear, angular) commands), `GoalServer`,
//! `ArenaSimulation`, `NavMonitor`, and `FaultInjector` (a deliberately faulty
//! behaviour for testing the runtime iB2C checks). The hardware drivers of the manifest (`Lidar`,
//! `WheelOdometry`, `BatteryMonitor`, `DiffDrive`) and `Explore` / `Dock` are not: the
//! simulation stands in for the hardware.

#![forbid(unsafe_code)]

mod behaviours;
mod fusion;
mod monitor;
mod simulation;

pub use behaviours::{AvoidObstacles, FaultInjector, FollowWall, GoToGoal};
pub use fusion::VelocityFusion;
pub use monitor::NavMonitor;
pub use simulation::{ArenaSimulation, GoalServer};

use ferroc_runtime::builder::Registry;

/// A planar pose in the map frame: metres, and radians counter-clockwise from x.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, bytemuck::NoUninit, serde::Serialize, serde::Deserialize,
)]
#[repr(C)]
pub struct Pose2D {
    /// Metres.
    pub x: f64,
    /// Metres.
    pub y: f64,
    /// Heading, radians counter-clockwise from the x axis.
    pub theta: f64,
}

ferroc_runtime::port_value!(Pose2D, "nav_behaviours.Pose2D", copy);

/// One sweep of a planar range sensor: `ranges[i]` is the distance along the direction
/// `angle_min + i · angle_increment` relative to the robot's heading.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RangeScan {
    /// Distances in metres (`max_range` where nothing is in range).
    pub ranges: Vec<f64>,
    /// Direction of the first beam, radians relative to the heading.
    pub angle_min: f64,
    /// Angle between two beams.
    pub angle_increment: f64,
    /// The sensor's range.
    pub max_range: f64,
}

ferroc_runtime::port_value!(RangeScan, "nav_behaviours.RangeScan", pooled);

impl RangeScan {
    /// The shortest range among the beams whose direction lies in `[from, to]` radians
    /// relative to the heading (`max_range` if none does, or the scan is empty).
    pub fn min_in(&self, from: f64, to: f64) -> f64 {
        let mut best = self.max_range;
        for (i, r) in self.ranges.iter().enumerate() {
            let angle = wrap(self.angle_min + i as f64 * self.angle_increment);
            if angle >= from && angle <= to && *r < best {
                best = *r;
            }
        }
        best
    }
}

/// An angle wrapped into [-π, π).
pub fn wrap(angle: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    (angle + PI).rem_euclid(TAU) - PI
}

/// Registers every implemented module type of this library.
pub fn register(registry: &mut Registry) {
    registry
        .register_behaviour::<GoToGoal>()
        .register_behaviour::<AvoidObstacles>()
        .register_behaviour::<FollowWall>()
        .register_behaviour::<VelocityFusion>()
        .register_behaviour::<FaultInjector>()
        .register::<GoalServer>()
        .register::<ArenaSimulation>()
        .register::<NavMonitor>()
        // Its value types with their serde form, as the manifest declares (serde="true"):
        // flexible ports (`ferroc_std.Dump`, `Logger`, …), recorders and bundles encode them.
        .register_serde::<Pose2D>()
        .register_serde::<RangeScan>();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sectors_of_a_scan() {
        let scan = RangeScan {
            ranges: vec![1.0, 2.0, 3.0, 4.0],
            angle_min: -std::f64::consts::PI,
            angle_increment: std::f64::consts::FRAC_PI_2,
            max_range: 5.0,
        };
        // beams at -180°, -90°, 0°, 90°
        assert_eq!(scan.min_in(-0.1, 0.1), 3.0);
        assert_eq!(scan.min_in(-1.6, 1.6), 2.0);
        assert_eq!(scan.min_in(0.1, 0.2), 5.0);
        assert_eq!(RangeScan::default().min_in(-1.0, 1.0), 0.0);
    }

    #[test]
    fn angles_wrap() {
        assert!((wrap(3.0 * std::f64::consts::PI) + std::f64::consts::PI).abs() < 1e-12);
        assert_eq!(wrap(0.5), 0.5);
    }
}
