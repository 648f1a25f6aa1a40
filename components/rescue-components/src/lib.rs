//! The rescue robot of `components/rescue.lib.xml` for ferroc: simulated drivers,
//! localization, mapping, victim detection, planning and mission control.
//!
//! The drivers talk to a simulated robot in a three-room building with three victims
//! ([`world`], [`hardware`]); everything above them is ordinary robot software that only
//! sees scans, frames and odometry. The simulation advances by a fixed step per base
//! control step, never by wall-clock time, and uses no randomness.

#![forbid(unsafe_code)]

mod camera;
mod console;
mod detector;
mod drivers;
mod fields;
mod grid;
mod hardware;
mod localizer;
mod mapper;
mod mission;
mod planner;
mod types;
mod world;

pub use camera::Camera;
pub use console::OperatorConsole;
pub use detector::VictimDetector;
pub use drivers::{BaseDriver, LaserDriver};
pub use fields::{register_fields, register_values};
pub use localizer::Localizer;
pub use mapper::Mapper;
pub use mission::{MissionContext, MissionManager};
pub use planner::PathPlanner;
pub use types::{Image, LaserScan, Map, Pose2D, Velocity2D, Victim, VictimList};
pub use world::START;

use ferroc_runtime::builder::Registry;

/// Registers every module type of this library, the fields connections may take
/// apart ([`register_fields`]) and the value types for flexible modules
/// ([`register_values`]).
pub fn register(registry: &mut Registry) {
    registry
        .register::<LaserDriver>()
        .register::<Camera>()
        .register::<BaseDriver>()
        .register::<Localizer>()
        .register::<Mapper>()
        .register::<VictimDetector>()
        .register::<PathPlanner>()
        .register::<MissionContext>()
        .register::<MissionManager>()
        .register::<OperatorConsole>();
    register_fields(registry);
    register_values(registry);
}
