//! The simulated robot hardware that the drivers talk to.
//!
//! On a real robot the laser, the camera and the motor board observe one physical
//! robot. Here that robot is simulated: one [`Robot`] per process, shared by the
//! driver modules as the physical robot is shared by their devices. Only the base
//! driver moves it (by a fixed [`PHYSICS_STEP`] per control step, never by wall-clock
//! time), so its motion is reproducible for a given sequence of commands.

use crate::types::{wrap_angle, Pose2D};
use crate::world::{World, START};
use std::collections::VecDeque;
use std::sync::{Mutex, MutexGuard, OnceLock, PoisonError};
use std::time::Duration;

/// Model time the base advances per control step: the period of the `drivers`
/// thread container of `models/rescue_robot.xml` (25 ms, 40 Hz).
pub const PHYSICS_STEP: Duration = Duration::from_millis(25);
/// Radius of the robot's round body.
pub const BODY_RADIUS: f64 = 0.25;
/// The gyro over-reads turns by this factor: odometry drifts in heading, which the
/// localizer corrects from the walls.
pub const GYRO_SCALE: f64 = 1.03;
/// Battery voltage when full.
pub const FULL_BATTERY: f64 = 25.2;
/// How many past poses are kept (for sensors with latency): 0.5 s.
const HISTORY: usize = 20;

/// The physical robot in its building, and the model time.
pub struct Robot {
    /// The building.
    pub world: World,
    /// Model time since the start.
    pub time: Duration,
    /// True pose.
    pub pose: Pose2D,
    /// What the wheel encoders and gyro integrate (drifts in heading).
    pub odometry: Pose2D,
    /// Volts.
    pub battery: f64,
    /// Pressed while the body touches a wall.
    pub bumper: bool,
    /// Recent true poses, newest last, with their times.
    history: VecDeque<(Duration, Pose2D)>,
}

impl Default for Robot {
    fn default() -> Self {
        let pose = Pose2D {
            x: START.0,
            y: START.1,
            theta: START.2,
        };
        Robot {
            world: World::building(),
            time: Duration::ZERO,
            pose,
            odometry: Pose2D::default(),
            battery: FULL_BATTERY,
            bumper: false,
            history: VecDeque::from([(Duration::ZERO, pose)]),
        }
    }
}

impl Robot {
    /// Drives for `dt` with the given forward (m/s) and turn (rad/s) velocity. The
    /// body stops where it would touch a wall (the bumper is pressed).
    pub fn step(&mut self, linear: f64, angular: f64, dt: Duration) {
        let dt_s = dt.as_secs_f64();
        let theta = wrap_angle(self.pose.theta + angular * dt_s);
        let mid = self.pose.theta + angular * dt_s / 2.0;
        let next = (
            self.pose.x + linear * mid.cos() * dt_s,
            self.pose.y + linear * mid.sin() * dt_s,
        );
        self.bumper = self.world.clearance(next) < BODY_RADIUS;
        let moved = if self.bumper { 0.0 } else { linear * dt_s };
        if !self.bumper {
            (self.pose.x, self.pose.y) = next;
        }
        self.pose.theta = theta;
        // Odometry: the wheels report the distance they rolled, the gyro over-reads.
        let odo_theta = self.odometry.theta + angular * dt_s * GYRO_SCALE;
        let odo_mid = (self.odometry.theta + odo_theta) / 2.0;
        self.odometry.x += moved * odo_mid.cos();
        self.odometry.y += moved * odo_mid.sin();
        self.odometry.theta = wrap_angle(odo_theta);
        // Electronics draw 5 mV/s, driving 20 mV per metre.
        self.battery -= 0.005 * dt_s + 0.02 * moved.abs();
        self.time += dt;
        self.history.push_back((self.time, self.pose));
        if self.history.len() > HISTORY {
            self.history.pop_front();
        }
    }

    /// The true pose `ago` before now (the oldest one kept if that is too long ago).
    pub fn pose_ago(&self, ago: Duration) -> Pose2D {
        let at = self.time.saturating_sub(ago);
        self.history
            .iter()
            .rev()
            .find(|(t, _)| *t <= at)
            .or(self.history.front())
            .map_or(self.pose, |(_, p)| *p)
    }
}

/// The robot of this process.
pub fn robot() -> MutexGuard<'static, Robot> {
    static ROBOT: OnceLock<Mutex<Robot>> = OnceLock::new();
    ROBOT
        .get_or_init(Mutex::default)
        .lock()
        // A driver that panicked while holding it left a consistent enough robot:
        // every field is assigned whole.
        .unwrap_or_else(PoisonError::into_inner)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn driving_straight_and_turning_integrate_the_velocity() {
        let mut r = Robot::default();
        for _ in 0..40 {
            r.step(0.5, 0.0, PHYSICS_STEP); // 1 s at 0.5 m/s, facing east
        }
        assert!((r.pose.x - (START.0 + 0.5)).abs() < 1e-9, "{:?}", r.pose);
        assert!(r.pose.y.abs() < 1e-9);
        assert_eq!(r.time, Duration::from_secs(1));
        for _ in 0..40 {
            r.step(0.0, std::f64::consts::FRAC_PI_2, PHYSICS_STEP); // a quarter turn
        }
        assert!((r.pose.theta - std::f64::consts::FRAC_PI_2).abs() < 1e-9);
        // The gyro over-reads by 3 %.
        assert!((r.odometry.theta - std::f64::consts::FRAC_PI_2 * GYRO_SCALE).abs() < 1e-9);
        // Odometry measured the straight metre half exactly.
        assert!((r.odometry.x - 0.5).abs() < 1e-9);
        assert!(r.battery < FULL_BATTERY);
    }

    #[test]
    fn a_wall_stops_the_body_and_presses_the_bumper() {
        let mut r = Robot::default();
        r.pose.theta = std::f64::consts::PI; // the west wall is 2 m away
        for _ in 0..200 {
            r.step(1.0, 0.0, PHYSICS_STEP);
        }
        assert!(r.bumper);
        assert!(r.pose.x >= -6.0 + BODY_RADIUS - 1e-9, "{:?}", r.pose);
        assert!(r.pose.x < -6.0 + BODY_RADIUS + 0.03, "{:?}", r.pose);
    }

    #[test]
    fn past_poses_are_remembered() {
        let mut r = Robot::default();
        for _ in 0..4 {
            r.step(1.0, 0.0, PHYSICS_STEP);
        }
        // 50 ms ago the robot had driven 2 steps of 25 mm.
        let p = r.pose_ago(Duration::from_millis(50));
        assert!((p.x - (START.0 + 0.05)).abs() < 1e-9, "{p:?}");
        // Longer ago than remembered: the oldest pose kept.
        assert_eq!(r.pose_ago(Duration::from_secs(60)).x, START.0);
    }
}
