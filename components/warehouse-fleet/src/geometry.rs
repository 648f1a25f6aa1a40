//! Plane geometry shared by the behaviours and the executor: angle wrapping and the
//! pure-pursuit steering law along a path.

use crate::Pose2D;
use std::f64::consts::{PI, TAU};

/// An angle wrapped into [-π, π).
pub fn wrap(angle: f64) -> f64 {
    (angle + PI).rem_euclid(TAU) - PI
}

/// Pure pursuit along a polyline path: steer on the arc through the point `lookahead`
/// metres ahead on the path.
///
/// The path is the warehouse's aisle grid way from where the goal was set: first along
/// x, then along y (aisles run along x, cross aisles along y), so robots keep to the
/// aisles instead of cutting diagonally through the racks.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PurePursuit {
    waypoints: Vec<(f64, f64)>,
}

/// What pure pursuit asks for in one step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Steering {
    /// Path curvature to follow, 1/m (positive: turn left).
    pub curvature: f64,
    /// Heading error towards the lookahead point, radians.
    pub heading_error: f64,
    /// Distance left along the path, metres.
    pub remaining: f64,
}

impl PurePursuit {
    /// A path from `start` to `goal` along the aisle grid (x first, then y).
    pub fn grid(start: Pose2D, goal: Pose2D) -> Self {
        let mut waypoints = vec![(start.x, start.y)];
        let corner = (goal.x, start.y);
        let far = |a: (f64, f64), b: (f64, f64)| (a.0 - b.0).hypot(a.1 - b.1) > 1e-6;
        if far(corner, waypoints[0]) && far(corner, (goal.x, goal.y)) {
            waypoints.push(corner);
        }
        waypoints.push((goal.x, goal.y));
        PurePursuit { waypoints }
    }

    /// The waypoints, start first.
    pub fn waypoints(&self) -> &[(f64, f64)] {
        &self.waypoints
    }

    /// The closest point of the path to `(x, y)`: segment index and parameter in [0, 1].
    fn project(&self, x: f64, y: f64) -> (usize, f64) {
        let mut best = (0, 0.0, f64::INFINITY);
        for (i, w) in self.waypoints.windows(2).enumerate() {
            let (ax, ay, bx, by) = (w[0].0, w[0].1, w[1].0, w[1].1);
            let (dx, dy) = (bx - ax, by - ay);
            let len2 = dx * dx + dy * dy;
            let t = if len2 > 0.0 {
                (((x - ax) * dx + (y - ay) * dy) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let d = (ax + t * dx - x).hypot(ay + t * dy - y);
            // Later segments win ties: at a corner the robot is already on the next one.
            if d <= best.2 {
                best = (i, t, d);
            }
        }
        (best.0, best.1)
    }

    /// The point `lookahead` metres along the path from the projection of `(x, y)`,
    /// and the path length from the projection to the end.
    fn ahead(&self, x: f64, y: f64, lookahead: f64) -> ((f64, f64), f64) {
        let Some(&last) = self.waypoints.last() else {
            return ((x, y), 0.0);
        };
        let (segment, t) = self.project(x, y);
        let mut remaining = 0.0;
        let mut target = None;
        let mut left = lookahead;
        for (i, w) in self.waypoints.windows(2).enumerate().skip(segment) {
            let (a, b) = (w[0], w[1]);
            let len = (b.0 - a.0).hypot(b.1 - a.1);
            let from = if i == segment { t * len } else { 0.0 };
            let rest = len - from;
            remaining += rest;
            if target.is_none() {
                if rest >= left && len > 0.0 {
                    let s = (from + left) / len;
                    target = Some((a.0 + s * (b.0 - a.0), a.1 + s * (b.1 - a.1)));
                } else {
                    left -= rest;
                }
            }
        }
        (target.unwrap_or(last), remaining)
    }

    /// Steering for a robot at `pose`.
    pub fn steer(&self, pose: Pose2D, lookahead: f64) -> Steering {
        let ((tx, ty), remaining) = self.ahead(pose.x, pose.y, lookahead);
        let (dx, dy) = (tx - pose.x, ty - pose.y);
        let distance = dx.hypot(dy);
        let heading_error = if distance > 1e-9 {
            wrap(dy.atan2(dx) - pose.theta)
        } else {
            0.0
        };
        // The arc through the target point: κ = 2 sin α / d.
        let curvature = if distance > 1e-9 {
            2.0 * heading_error.sin() / distance
        } else {
            0.0
        };
        Steering {
            curvature,
            heading_error,
            remaining,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pose(x: f64, y: f64, theta: f64) -> Pose2D {
        Pose2D { x, y, theta }
    }

    #[test]
    fn angles_wrap_into_one_turn() {
        assert!((wrap(3.0 * PI) + PI).abs() < 1e-12);
        assert_eq!(wrap(0.5), 0.5);
        assert!((wrap(-0.5 - TAU) + 0.5).abs() < 1e-12);
    }

    #[test]
    fn grid_paths_go_along_x_then_y() {
        let path = PurePursuit::grid(pose(0.0, 0.0, 0.0), pose(4.0, 3.0, 0.0));
        assert_eq!(path.waypoints(), &[(0.0, 0.0), (4.0, 0.0), (4.0, 3.0)]);
        // Already in the goal's aisle: a straight line.
        let path = PurePursuit::grid(pose(0.0, 3.0, 0.0), pose(4.0, 3.0, 0.0));
        assert_eq!(path.waypoints(), &[(0.0, 3.0), (4.0, 3.0)]);
    }

    #[test]
    fn steering_on_and_off_the_path() {
        let path = PurePursuit::grid(pose(0.0, 0.0, 0.0), pose(4.0, 3.0, 0.0));
        // On the path, heading along it: straight ahead, 7 m to go.
        let s = path.steer(pose(0.0, 0.0, 0.0), 0.5);
        assert!(s.curvature.abs() < 1e-12 && s.heading_error.abs() < 1e-12);
        assert!((s.remaining - 7.0).abs() < 1e-9);
        // Right of the path (y < 0): turn left.
        let s = path.steer(pose(1.0, -0.2, 0.0), 0.5);
        assert!(s.curvature > 0.0 && s.heading_error > 0.0);
        // Near the corner the lookahead point lies on the second leg: turn left.
        let s = path.steer(pose(3.8, 0.0, 0.0), 0.5);
        assert!(s.heading_error > 0.5, "{s:?}");
        assert!((s.remaining - 3.2).abs() < 1e-9);
        // Facing away from the goal: the error is behind the robot.
        let s = path.steer(pose(4.0, 2.0, -PI / 2.0), 0.5);
        assert!(s.heading_error.abs() > 3.0, "{s:?}");
        // At the end: nothing left.
        assert!(path.steer(pose(4.0, 3.0, 0.0), 0.5).remaining < 1e-9);
    }
}
