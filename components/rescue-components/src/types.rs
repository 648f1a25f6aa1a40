//! The library's data types (`<type>` in `components/rescue.lib.xml`).
//!
//! Time stamps are model time since the start of the simulation, not wall-clock time,
//! so that a run is reproducible.

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

impl Pose2D {
    /// Distance between the positions of two poses.
    pub fn distance_to(&self, other: &Pose2D) -> f64 {
        (self.x - other.x).hypot(self.y - other.y)
    }
}

/// Forward and turn velocity of a differential-drive base.
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::NoUninit, Serialize, Deserialize)]
#[repr(C)]
pub struct Velocity2D {
    /// m/s.
    pub linear: f64,
    /// rad/s, counter-clockwise positive.
    pub angular: f64,
}

/// One sweep of a planar laser range finder.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct LaserScan {
    /// Model time of the measurement.
    pub stamp: Duration,
    /// Bearing of the first beam relative to the robot's heading (rad).
    pub angle_min: f64,
    /// Angle between two beams (rad).
    pub angle_increment: f64,
    /// Metres; a beam that hits nothing reads the maximum range.
    pub ranges: Vec<f32>,
    /// Reflectivity of what each beam hit (0..1).
    pub intensities: Vec<f32>,
}

impl LaserScan {
    /// Bearing of beam `i` relative to the robot's heading.
    pub fn bearing(&self, i: usize) -> f64 {
        self.angle_min + self.angle_increment * i as f64
    }

    /// The range measured closest to `bearing` (None for an empty scan or a bearing
    /// outside the sweep).
    pub fn range_at(&self, bearing: f64) -> Option<f64> {
        if self.ranges.is_empty() || self.angle_increment <= 0.0 {
            return None;
        }
        let i = ((bearing - self.angle_min) / self.angle_increment).round();
        if !(0.0..self.ranges.len() as f64).contains(&i) {
            return None;
        }
        self.ranges.get(i as usize).map(|&r| f64::from(r))
    }
}

/// A raw grey-scale camera frame, row by row. Not serialisable: it stays on the robot.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Image {
    /// Model time of the exposure.
    pub stamp: Duration,
    /// Pixels per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// `width * height` brightness values, row-major.
    pub pixels: Vec<u8>,
}

/// One detected victim. The fields are ordered largest first (not as the manifest lists
/// them) so that the `#[repr(C)]` layout has no padding, which the copy path requires.
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::NoUninit, Serialize, Deserialize)]
#[repr(C)]
pub struct Victim {
    /// Map frame, metres.
    pub x: f64,
    /// Map frame, metres.
    pub y: f64,
    /// Number given by the detector, from 1.
    pub id: u32,
    /// Best detection confidence so far (0..1).
    pub confidence: f32,
}

/// All victims detected so far.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct VictimList {
    /// Model time of the latest detection.
    pub stamp: Duration,
    /// In the order they were found.
    pub victims: Vec<Victim>,
}

/// Occupancy grid: -1 unknown, 0 free .. 100 occupied; row-major from the origin.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Map {
    /// Edge length of a cell (m).
    pub resolution: f64,
    /// Cells per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Map-frame position of the corner of cell (0, 0).
    pub origin: Pose2D,
    /// `width * height` cells.
    pub cells: Vec<i8>,
}

/// Value of a cell nobody has seen.
pub const UNKNOWN: i8 = -1;
/// Cells at or above this value count as occupied.
pub const OCCUPIED: i8 = 50;

impl Map {
    /// The cell holding the map-frame point (x, y), if it lies on the map.
    pub fn cell_of(&self, x: f64, y: f64) -> Option<(u32, u32)> {
        if self.resolution <= 0.0 {
            return None;
        }
        let cx = ((x - self.origin.x) / self.resolution).floor();
        let cy = ((y - self.origin.y) / self.resolution).floor();
        let inside = (0.0..f64::from(self.width)).contains(&cx)
            && (0.0..f64::from(self.height)).contains(&cy);
        inside.then_some((cx as u32, cy as u32))
    }

    /// The value of cell (cx, cy); unknown outside the map.
    pub fn get(&self, cx: u32, cy: u32) -> i8 {
        if cx >= self.width || cy >= self.height {
            return UNKNOWN;
        }
        let i = cy as usize * self.width as usize + cx as usize;
        self.cells.get(i).copied().unwrap_or(UNKNOWN)
    }

    /// Map-frame centre of cell (cx, cy).
    pub fn centre_of(&self, cx: u32, cy: u32) -> (f64, f64) {
        (
            self.origin.x + (f64::from(cx) + 0.5) * self.resolution,
            self.origin.y + (f64::from(cy) + 0.5) * self.resolution,
        )
    }
}

ferroc_runtime::port_value!(Pose2D, "rescue.Pose2D", copy);
ferroc_runtime::port_value!(Velocity2D, "rescue.Velocity2D", copy);
ferroc_runtime::port_value!(Victim, "rescue.Victim", copy);
ferroc_runtime::port_value!(LaserScan, "rescue.LaserScan", pooled);
ferroc_runtime::port_value!(Image, "rescue.Image", pooled);
ferroc_runtime::port_value!(VictimList, "rescue.VictimList", pooled);
ferroc_runtime::port_value!(Map, "rescue.Map", pooled);

/// Wraps an angle into (-π, π].
pub fn wrap_angle(a: f64) -> f64 {
    let tau = std::f64::consts::TAU;
    let mut w = a.rem_euclid(tau);
    if w > std::f64::consts::PI {
        w -= tau;
    }
    w
}
