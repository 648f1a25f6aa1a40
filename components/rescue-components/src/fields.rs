//! The numeric fields of this library's copy types that a model may take apart on a
//! connection (`<convert field="linear"/>` from a `Velocity2D` output to an `f64`
//! input), and the value types flexible modules (`ferroc_std.Logger`, `Dump`) may make
//! ports of.

use crate::types::{Image, LaserScan, Map, Pose2D, Velocity2D, Victim, VictimList};
use ferroc_runtime::builder::Registry;

/// Registers every numeric field of `Pose2D`, `Velocity2D` and `Victim`. Called by
/// [`crate::register`]; public for binaries that register module types one by one.
pub fn register_fields(registry: &mut Registry) {
    registry
        .register_field::<Pose2D, f64>("x", |p| p.x)
        .register_field::<Pose2D, f64>("y", |p| p.y)
        .register_field::<Pose2D, f64>("theta", |p| p.theta)
        .register_field::<Velocity2D, f64>("linear", |v| v.linear)
        .register_field::<Velocity2D, f64>("angular", |v| v.angular)
        .register_field::<Victim, u32>("id", |v| v.id)
        .register_field::<Victim, f64>("x", |v| v.x)
        .register_field::<Victim, f64>("y", |v| v.y)
        .register_field::<Victim, f32>("confidence", |v| v.confidence);
}

/// Registers every value type of the library for flexible modules'
/// ports (`models/rescue_robot.xml` logs victim lists on the station).
pub fn register_values(registry: &mut Registry) {
    registry
        .register_serde::<Pose2D>()
        .register_serde::<Velocity2D>()
        .register_serde::<LaserScan>()
        .register_value::<Image>()
        .register_serde::<Victim>()
        .register_serde::<VictimList>()
        .register_serde::<Map>();
}
