//! The data types of `rescue` (manifest: `components/rescue.lib.xml`) that the warehouse
//! library uses: [`Pose2D`] and [`LaserScan`].
//!
//! Only these two: the warehouse crate needs them to exist under the `rust=` paths its
//! manifest inherits (`rescue_components::Pose2D`). The rescue module types are not here;
//! the full rescue crate (branch `rescue`) replaces this one: its `Pose2D` and
//! `LaserScan` are these (same fields, order and derives; `Pose2D::distance_to`).

use serde::{Deserialize, Serialize};
use std::time::Duration;

/// A planar pose in the map frame: metres, and radians counter-clockwise from x.
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::NoUninit, Serialize, Deserialize)]
#[repr(C)]
pub struct Pose2D {
    /// Metres.
    pub x: f64,
    /// Metres.
    pub y: f64,
    /// Heading, radians counter-clockwise from the x axis.
    pub theta: f64,
}

ferroc_runtime::port_value!(Pose2D, "rescue.Pose2D", copy);

/// One sweep of a planar laser range finder: `ranges[i]` lies along
/// `angle_min + i · angle_increment`, relative to the sensor's heading.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct LaserScan {
    /// When the sweep was measured (time since the start of the sensor's clock).
    pub stamp: Duration,
    /// Direction of the first beam, radians.
    pub angle_min: f64,
    /// Angle between two beams, radians.
    pub angle_increment: f64,
    /// Metres.
    pub ranges: Vec<f32>,
    /// Reflectivity per beam (sensor units).
    pub intensities: Vec<f32>,
}

ferroc_runtime::port_value!(LaserScan, "rescue.LaserScan", pooled);

impl Pose2D {
    /// Distance between the positions of two poses.
    pub fn distance_to(&self, other: &Pose2D) -> f64 {
        (other.x - self.x).hypot(other.y - self.y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ferroc_runtime::module::PortValue;

    #[test]
    fn model_names_and_distance() {
        assert_eq!(Pose2D::model_type(), "rescue.Pose2D");
        assert_eq!(LaserScan::model_type(), "rescue.LaserScan");
        let a = Pose2D::default();
        let b = Pose2D {
            x: 3.0,
            y: 4.0,
            theta: 1.0,
        };
        assert_eq!(a.distance_to(&b), 5.0);
    }
}
