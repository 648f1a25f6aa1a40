//! `rescue.Localizer`: tracks the pose from odometry and corrects the heading drift of
//! the gyro from the walls in the laser scan.
//!
//! The building's walls run north-south and east-west (a "Manhattan" world). Each
//! update scores `particles` heading hypotheses around the odometry heading by how well
//! the scan's wall segments line up with the axes, and takes the best. Position error
//! left by the heading error is not corrected; the covariance says so by growing with
//! the distance driven.

use crate::types::{wrap_angle, LaserScan, Pose2D};
use ferroc_runtime::module::{In, Kind, Module, ModuleType, Out, Parameter, Setup};
use ferroc_runtime::service::ServicePort;

/// Hypotheses are searched this far either side of the odometry heading (rad).
const SEARCH: f64 = 0.1;
/// Heading variance after a correction (rad²), and how it grows per radian turned.
const CORRECTED_VARIANCE: f64 = 1e-4;
/// Position variance added per metre driven (m²/m).
const DRIFT_PER_METRE: f64 = 0.002;
/// A relocalization succeeds when the walls align at least this well from the hint.
const RELOCALIZED: f64 = 0.9;
/// A global relocalization searches headings this far either side of the hint's.
const GLOBAL_SEARCH: f64 = std::f64::consts::FRAC_PI_4;

/// How well the scan's wall segments align with the map axes if the robot's heading
/// is `heading`: 1 perfectly, about 0 for no structure.
pub fn axis_alignment(scan: &LaserScan, heading: f64) -> f64 {
    // Only beams that hit something: no return reads +∞ (REP 117) or, from sensors
    // that report the maximum range instead, has intensity 0.
    let points: Vec<(f64, f64)> = scan
        .ranges
        .iter()
        .enumerate()
        .filter(|(_, r)| r.is_finite() && **r > 0.0)
        .filter(|(i, _)| scan.intensities.get(*i).is_none_or(|&x| x > 0.0))
        .map(|(i, &r)| {
            let a = heading + scan.bearing(i);
            (f64::from(r) * a.cos(), f64::from(r) * a.sin())
        })
        .collect();
    let (mut sum, mut weight) = (0.0, 0.0);
    for t in points.windows(3) {
        let (a, b) = (
            (t[1].0 - t[0].0, t[1].1 - t[0].1),
            (t[2].0 - t[1].0, t[2].1 - t[1].1),
        );
        let (la, lb) = (a.0.hypot(a.1), b.0.hypot(b.1));
        // Points more than half a metre apart lie on different walls; a bend between
        // the two halves is a corner, whose direction is no wall's.
        if la < 1e-6 || lb < 1e-6 || la > 0.5 || lb > 0.5 {
            continue;
        }
        if (a.0 * b.1 - a.1 * b.0).abs() / (la * lb) > 0.05 {
            continue;
        }
        let (dx, dy) = (t[2].0 - t[0].0, t[2].1 - t[0].1);
        // cos(4α) is 1 for directions along either axis.
        sum += (la + lb) * (4.0 * dy.atan2(dx)).cos();
        weight += la + lb;
    }
    if weight > 0.0 {
        sum / weight
    } else {
        0.0
    }
}

/// The heading among `hypotheses` evenly spread over ±[`SEARCH`] around `guess` that
/// best aligns the scan with the axes (ties: the one closest to `guess`).
pub fn best_heading(scan: &LaserScan, guess: f64, hypotheses: u32) -> f64 {
    let n = hypotheses.max(2);
    let mut best = (axis_alignment(scan, guess), guess);
    for k in 0..n {
        let h = guess - SEARCH + 2.0 * SEARCH * f64::from(k) / f64::from(n - 1);
        let score = axis_alignment(scan, h);
        if score > best.0 + 1e-9 {
            best = (score, h);
        }
    }
    best.1
}

/// Dead reckoning on odometry with heading corrections from the walls.
pub struct Localizer {
    scan: In<LaserScan>,
    odometry: In<Pose2D>,
    pose_out: Out<Pose2D>,
    covariance: Out<[f64; 3]>,
    reset_pose: In<Pose2D>,
    localized: Out<bool>,
    relocalize: ServicePort<Pose2D, bool>,
    particles: Parameter<u32>,
    update_distance: Parameter<f64>,
    update_angle: Parameter<f64>,
    /// The estimate, in the map frame.
    pose: Pose2D,
    /// Odometry at the last step, and at the last correction.
    last_odometry: Option<Pose2D>,
    at_correction: Pose2D,
    variance: [f64; 3],
}

impl ModuleType for Localizer {
    const NAME: &'static str = "rescue.Localizer";
    const KIND: Kind = Kind::SenseControl;
    const DOC: &'static str = "Monte-Carlo localization on the current map";

    // `update_angle`'s bound is the manifest's 3.14, not π: they must agree exactly.
    #[allow(clippy::approx_constant)]
    fn create(m: &mut Setup<'_>) -> Self {
        let start = crate::world::START;
        Localizer {
            scan: m.sensor_input("scan").required().build(),
            odometry: m.sensor_input("odometry").required().build(),
            pose_out: m.sensor_output("pose").build(),
            covariance: m
                .sensor_output("covariance")
                .doc("variances of x, y (m^2) and theta (rad^2)")
                .build(),
            reset_pose: m
                .controller_input("reset_pose")
                .doc("re-initialise the filter around this pose")
                .build(),
            localized: m.controller_output("localized").build(),
            relocalize: m
                .service("relocalize")
                .doc("global relocalization around a hint pose")
                .build(),
            particles: m
                .param("particles")
                .range(50.0, 10000.0)
                .default(500)
                .build(),
            update_distance: m
                .param("update_distance")
                .unit("m")
                .range(0.0, 2.0)
                .default(0.2)
                .build(),
            update_angle: m
                .param("update_angle")
                .unit("rad")
                .range(0.0, 3.14)
                .default(0.1)
                .build(),
            // The robot is placed at the known start pose of its building.
            pose: Pose2D {
                x: start.0,
                y: start.1,
                theta: start.2,
            },
            last_odometry: None,
            at_correction: Pose2D::default(),
            variance: [0.0; 3],
        }
    }
}

impl Localizer {
    /// Moves the estimate by the odometry increment since the last step (rotated into
    /// the map frame: odometry starts at zero, the map at the start pose).
    fn predict(&mut self, odometry: Pose2D) {
        let Some(last) = self.last_odometry.replace(odometry) else {
            self.at_correction = odometry;
            return;
        };
        let (dx, dy) = (odometry.x - last.x, odometry.y - last.y);
        let forward = dx.hypot(dy);
        let direction = dy.atan2(dx) - last.theta; // of the motion, in the robot frame
        let heading = self.pose.theta + direction;
        self.pose.x += forward * heading.cos();
        self.pose.y += forward * heading.sin();
        let turn = wrap_angle(odometry.theta - last.theta);
        self.pose.theta = wrap_angle(self.pose.theta + turn);
        self.variance[0] += DRIFT_PER_METRE * forward;
        self.variance[1] += DRIFT_PER_METRE * forward;
        self.variance[2] += 0.03f64.powi(2) * turn.abs();
    }
}

/// The heading that best aligns `scan` with the axes within ±[`GLOBAL_SEARCH`] of
/// `hint`, and how well it aligns; `None` for a hint that is not a pose.
pub fn relocalize(scan: &LaserScan, hint: &Pose2D, hypotheses: u32) -> Option<(f64, f64)> {
    if !(hint.x.is_finite() && hint.y.is_finite() && hint.theta.is_finite()) {
        return None;
    }
    // Coarse steps over the wide window, then the fine search around the best.
    let n = hypotheses.clamp(2, 10_000);
    let coarse = (0..n)
        .map(|k| hint.theta - GLOBAL_SEARCH + 2.0 * GLOBAL_SEARCH * f64::from(k) / f64::from(n - 1))
        .max_by(|a, b| axis_alignment(scan, *a).total_cmp(&axis_alignment(scan, *b)))?;
    let heading = best_heading(scan, coarse, n);
    Some((wrap_angle(heading), axis_alignment(scan, heading)))
}

impl Module for Localizer {
    fn sense(&mut self) {
        // Relocalization requests from other modules: trust the hint's position, search
        // the heading on the latest scan; answer whether the walls confirm it.
        let scan = self.scan.get();
        let hypotheses = self.particles.get();
        let (pose, variance) = (&mut self.pose, &mut self.variance);
        self.relocalize
            .serve_pending(|hint| match relocalize(&scan, &hint, hypotheses) {
                Some((heading, score)) if score >= RELOCALIZED => {
                    *pose = Pose2D {
                        theta: heading,
                        ..hint
                    };
                    *variance = [0.0, 0.0, CORRECTED_VARIANCE];
                    true
                }
                _ => false,
            });
        let odometry = self.odometry.get();
        self.predict(odometry);
        let moved = odometry.distance_to(&self.at_correction);
        let turned = wrap_angle(odometry.theta - self.at_correction.theta).abs();
        if self.scan.changed()
            && (moved >= self.update_distance.get() || turned >= self.update_angle.get())
        {
            let scan = self.scan.get();
            self.pose.theta =
                wrap_angle(best_heading(&scan, self.pose.theta, self.particles.get()));
            self.variance[2] = CORRECTED_VARIANCE;
            self.at_correction = odometry;
        }
        self.pose_out.publish(self.pose);
        self.covariance.publish(self.variance);
    }

    fn control(&mut self) {
        if self.reset_pose.changed() {
            let p = self.reset_pose.get();
            if p.x.is_finite() && p.y.is_finite() && p.theta.is_finite() {
                self.pose = p;
                self.variance = [0.0, 0.0, CORRECTED_VARIANCE];
            }
        }
        // Localized while the heading is known to about 3°.
        self.localized.publish(self.variance[2] < 0.0025);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drivers::sweep;
    use crate::hardware::{Robot, PHYSICS_STEP};
    use std::time::Duration;

    #[test]
    fn the_true_heading_aligns_the_scan_best() {
        let robot = Robot::default();
        let mut pose = robot.pose;
        pose.theta = 0.3;
        let scan = sweep(&robot, &pose, 30.0, Duration::ZERO);
        assert!(axis_alignment(&scan, 0.3) > 0.99);
        // Turned by δ, every wall scores cos(4δ).
        assert!((axis_alignment(&scan, 0.3 + 0.2) - 0.8f64.cos()).abs() < 0.02);
        assert!(axis_alignment(&scan, 0.3 + 0.4) < 0.0);
        // From a guess 0.05 rad off, the search finds the truth within its step.
        let found = best_heading(&scan, 0.35, 201);
        assert!((found - 0.3).abs() <= 0.001 + 1e-9, "{found}");
    }

    #[test]
    fn relocalization_finds_the_heading_near_a_rough_hint() {
        let robot = Robot::default();
        let mut pose = robot.pose;
        pose.theta = 0.4;
        let scan = sweep(&robot, &pose, 30.0, Duration::ZERO);
        // 0.3 rad off: beyond the tracking window, within the global one.
        let hint = Pose2D { theta: 0.7, ..pose };
        let (heading, score) = relocalize(&scan, &hint, 500).unwrap();
        assert!(
            (heading - 0.4).abs() < 0.002 && score > 0.99,
            "{heading} {score}"
        );
        assert!(relocalize(
            &scan,
            &Pose2D {
                x: f64::NAN,
                ..hint
            },
            500
        )
        .is_none());
        // An empty scan confirms nothing.
        let (_, score) = relocalize(&LaserScan::default(), &hint, 500).unwrap();
        assert!(score < RELOCALIZED);
    }

    #[test]
    fn beams_without_a_return_are_no_walls() {
        // Only the wall ahead is in range; the other beams either read +∞ or, from a
        // sensor that reports the maximum range, 2 m with intensity 0: a ring that
        // must not pin the heading.
        let robot = Robot::default();
        let mut pose = robot.pose;
        pose.x = 1.0; // 1 m before the partition at x = 2
        let mut scan = sweep(&robot, &pose, 2.0, Duration::ZERO);
        assert!(scan.ranges.iter().any(|r| r.is_infinite()));
        let truth = best_heading(&scan, 0.05, 201);
        for (r, i) in scan.ranges.iter_mut().zip(&scan.intensities) {
            if *i == 0.0 {
                *r = 2.0;
            }
        }
        assert!((best_heading(&scan, 0.05, 201) - truth).abs() < 1e-9);
        assert!(truth.abs() < 0.002, "{truth}");
    }

    #[test]
    fn turning_with_a_drifting_gyro_is_corrected_by_the_walls() {
        let mut robot = Robot::default();
        let mut estimate = robot.pose;
        for _ in 0..40 {
            robot.step(0.2, 1.0, PHYSICS_STEP); // one radian in a second, arcing
        }
        // Odometry alone is 3 % off after a radian.
        let odometry_heading = estimate.theta + robot.odometry.theta;
        assert!((odometry_heading - robot.pose.theta).abs() > 0.025);
        let scan = sweep(&robot, &robot.pose, 30.0, robot.time);
        estimate.theta = best_heading(&scan, odometry_heading, 500);
        assert!(
            (estimate.theta - robot.pose.theta).abs() < 0.002,
            "{estimate:?}"
        );
    }
}
