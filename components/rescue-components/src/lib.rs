//! The rescue robot of `components/rescue.lib.xml` for ferroc: simulated drivers,
//! localization, mapping, victim detection, planning and mission control.
//!
//! The drivers talk to a simulated robot in a three-room building with three victims
//! ([`world`], [`hardware`]); everything above them is ordinary robot software that only
//! sees scans, frames and odometry. The simulation advances by a fixed step per base
//! control step, never by wall-clock time, and uses no randomness.
//!
//! Not implemented: the Localizer's `relocalize` service (module types cannot declare
//! services through `Setup` yet).

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
pub use fields::{register_fields, RegisterField};
pub use localizer::Localizer;
pub use mapper::Mapper;
pub use mission::{MissionContext, MissionManager};
pub use planner::PathPlanner;
pub use types::{Image, LaserScan, Map, Pose2D, Velocity2D, Victim, VictimList};
pub use world::START;

use ferroc_runtime::builder::Registry;

/// Registers every module type of this library. (The fields of its copy types follow
/// once the runtime can take them: [`register_fields`].)
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
}
