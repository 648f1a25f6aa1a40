//! The FINROC crash-course robot, ported to ferroc (manifest:
//! `components/crash_course.lib.xml`).
//!
//! A simulated two-wheeled robot drives in a square walled arena with an infrared
//! distance sensor at the front and one at the rear. Hitting a wall faster than the
//! destructive collision speed destroys it, and a new robot starts in the middle. The
//! controller looks around (turning in place while both rays sample the walls), then
//! drives straight only as far as its body's corridor is free (`plan.rs`).

#![forbid(unsafe_code)]

mod controller;
mod enable;
mod noise;
pub mod plan;
pub mod ros;
mod sensors;
mod simulation;
mod twist;
mod visualization;

pub use controller::Controller;
pub use enable::{Ack, EnableAsk, EnableSwitch};
pub use noise::AddNoise;
pub use ros::{
    Header, LaserScan, Odometry, Point, Pose, PoseStamped, PoseWithCovariance, Quaternion,
    TfMessage, Transform, TransformStamped, TwistWithCovariance,
};
pub use sensors::{LaserScanner, OdometryOut};
pub use simulation::MainSimulation;
pub use twist::{Twist, TwistOut, Vector3};
pub use visualization::Visualization;

use ferroc_runtime::builder::Registry;

/// A planar pose in the arena frame: metres, and radians counter-clockwise from x.
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
    pub yaw: f64,
}

ferroc_runtime::port_value!(Pose2D, "crash_course.Pose2D", copy);

/// Registers every module type of this library.
pub fn register(registry: &mut Registry) {
    registry
        .register::<MainSimulation>()
        .register::<AddNoise>()
        .register::<Visualization>()
        .register::<Controller>()
        .register::<TwistOut>()
        .register::<EnableSwitch>()
        .register::<EnableAsk>()
        .register::<LaserScanner>()
        .register::<OdometryOut>()
        // Its value type, for flexible ports (`ferroc_std.Dump`, `Logger`, `Player`, …)
        // and `--record`: with its serde form, so a recording holds the pose.
        .register_serde::<Pose2D>()
        .register_serde::<Vector3>()
        .register_serde::<Twist>()
        .register_serde::<Ack>()
        // The demo's ROS 2 messages (models/ros2_demo.xml).
        .register_serde::<Header>()
        .register_serde::<LaserScan>()
        .register_serde::<Point>()
        .register_serde::<Quaternion>()
        .register_serde::<Pose>()
        .register_serde::<PoseStamped>()
        .register_serde::<PoseWithCovariance>()
        .register_serde::<TwistWithCovariance>()
        .register_serde::<Odometry>()
        .register_serde::<Transform>()
        .register_serde::<TransformStamped>()
        .register_serde::<TfMessage>()
        // `EnableSwitch` answers a ROS 2 service and `EnableAsk` calls one: their calls
        // cross as JSON.
        .register_call::<bool, Ack>();
}
