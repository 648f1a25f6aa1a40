//! `warehouse.DiffDriveKinematics`: wheel odometry (sense) and body velocity → wheel
//! speeds (control) of a differential-drive chassis.

use crate::timing::IO_STEP;
use crate::{wrap, Pose2D};
use ferroc_runtime::module::{In, Kind, Module, ModuleType, Out, Parameter, Setup};
use std::f64::consts::TAU;

/// The wheel geometry of a differential drive. Wheel speeds are wheel revolutions per
/// minute (positive: forward), as on the ports.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Chassis {
    /// Metres.
    pub wheel_radius: f64,
    /// Distance between the wheels' contact points, metres.
    pub track_width: f64,
}

impl Chassis {
    fn rpm_to_mps(&self, rpm: f64) -> f64 {
        rpm * TAU * self.wheel_radius / 60.0
    }

    fn mps_to_rpm(&self, mps: f64) -> f64 {
        mps * 60.0 / (TAU * self.wheel_radius)
    }

    /// Forward (m/s) and turn (rad/s, positive: left) velocity from the wheel speeds.
    pub fn body_velocity(&self, left_rpm: f64, right_rpm: f64) -> (f64, f64) {
        let (l, r) = (self.rpm_to_mps(left_rpm), self.rpm_to_mps(right_rpm));
        ((l + r) / 2.0, (r - l) / self.track_width)
    }

    /// Wheel speeds for a body velocity. If a wheel would exceed `max_rpm`, both are
    /// scaled down by the same factor: slower, but on the same arc.
    pub fn wheel_speeds(&self, velocity: f64, angular: f64, max_rpm: f64) -> (f64, f64) {
        let half = angular * self.track_width / 2.0;
        let left = self.mps_to_rpm(velocity - half);
        let right = self.mps_to_rpm(velocity + half);
        let largest = left.abs().max(right.abs());
        if largest > max_rpm && largest > 0.0 {
            let k = max_rpm.max(0.0) / largest;
            (left * k, right * k)
        } else {
            (left, right)
        }
    }
}

/// Moves `pose` for `dt` seconds at constant forward and turn velocity, exactly along
/// the arc (a straight line when not turning).
pub fn integrate(pose: Pose2D, velocity: f64, angular: f64, dt: f64) -> Pose2D {
    let theta = pose.theta + angular * dt;
    let (dx, dy) = if angular.abs() > 1e-9 {
        let r = velocity / angular;
        (
            r * (theta.sin() - pose.theta.sin()),
            r * (pose.theta.cos() - theta.cos()),
        )
    } else {
        (
            velocity * dt * pose.theta.cos(),
            velocity * dt * pose.theta.sin(),
        )
    };
    Pose2D {
        x: pose.x + dx,
        y: pose.y + dy,
        theta: wrap(theta),
    }
}

/// A non-finite reading (a broken sensor) counts as standing still.
fn finite(x: f64) -> f64 {
    if x.is_finite() {
        x
    } else {
        0.0
    }
}

/// Differential-drive kinematics and wheel odometry.
///
/// The odometry frame starts at the origin where the robot is switched on; the
/// simulated wheels do not slip, so it is also the robot's true pose.
pub struct DiffDriveKinematics {
    left_measured: In<f64>,
    right_measured: In<f64>,
    odometry: Out<Pose2D>,
    speed: Out<f64>,
    velocity: In<f64>,
    angular_velocity: In<f64>,
    stop: In<bool>,
    left_speed: Out<f64>,
    right_speed: Out<f64>,
    wheel_radius: Parameter<f64>,
    track_width: Parameter<f64>,
    max_wheel_speed: Parameter<f64>,
    pose: Pose2D,
}

impl DiffDriveKinematics {
    fn chassis(&mut self) -> Chassis {
        Chassis {
            wheel_radius: self.wheel_radius.get(),
            track_width: self.track_width.get(),
        }
    }
}

impl ModuleType for DiffDriveKinematics {
    const NAME: &'static str = "warehouse.DiffDriveKinematics";
    const KIND: Kind = Kind::SenseControl;
    const DOC: &'static str = "Differential-drive kinematics and wheel odometry";

    fn create(m: &mut Setup<'_>) -> Self {
        DiffDriveKinematics {
            left_measured: m
                .sensor_input("left_measured")
                .unit("rpm")
                .required()
                .build(),
            right_measured: m
                .sensor_input("right_measured")
                .unit("rpm")
                .required()
                .build(),
            odometry: m.sensor_output("odometry").build(),
            speed: m.sensor_output("speed").unit("m/s").build(),
            velocity: m
                .controller_input("velocity")
                .unit("m/s")
                .required()
                .build(),
            angular_velocity: m
                .controller_input("angular_velocity")
                .unit("rad/s")
                .required()
                .build(),
            stop: m
                .controller_input("stop")
                .doc("true forces zero wheel speeds")
                .build(),
            left_speed: m.controller_output("left_speed").unit("rpm").build(),
            right_speed: m.controller_output("right_speed").unit("rpm").build(),
            // The ranges keep the divisions by radius and track width finite.
            wheel_radius: m.param("wheel_radius").unit("m").range(0.01, 1.0).build(),
            track_width: m.param("track_width").unit("m").range(0.05, 3.0).build(),
            max_wheel_speed: m
                .param("max_wheel_speed")
                .unit("rpm")
                .range(0.0, 6000.0)
                .default(3000.0)
                .build(),
            pose: Pose2D::default(),
        }
    }
}

impl Module for DiffDriveKinematics {
    fn sense(&mut self) {
        let chassis = self.chassis();
        let left = finite(self.left_measured.get());
        let right = finite(self.right_measured.get());
        let (v, w) = chassis.body_velocity(left, right);
        self.pose = integrate(self.pose, v, w, IO_STEP);
        self.odometry.publish(self.pose);
        self.speed.publish(v);
    }

    fn control(&mut self) {
        let chassis = self.chassis();
        let max = self.max_wheel_speed.get();
        let (left, right) = if *self.stop.get() {
            (0.0, 0.0)
        } else {
            let v = finite(self.velocity.get());
            let w = finite(self.angular_velocity.get());
            chassis.wheel_speeds(v, w, max)
        };
        self.left_speed.publish(left);
        self.right_speed.publish(right);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    const AGV: Chassis = Chassis {
        wheel_radius: 0.1,
        track_width: 0.48,
    };

    #[test]
    fn wheel_speeds_and_body_velocity_are_inverse() {
        let (l, r) = AGV.wheel_speeds(1.0, 0.5, 3000.0);
        // 1 m/s on a 0.1 m wheel is 95.5 rpm; turning left makes the right wheel faster.
        assert!(r > l);
        assert!(((l + r) / 2.0 - 60.0 / (TAU * 0.1)).abs() < 1e-9);
        let (v, w) = AGV.body_velocity(l, r);
        assert!((v - 1.0).abs() < 1e-12 && (w - 0.5).abs() < 1e-12);
    }

    #[test]
    fn the_wheel_limit_keeps_the_arc() {
        let (l, r) = AGV.wheel_speeds(2.0, 1.0, 100.0);
        assert!((r - 100.0).abs() < 1e-9, "{r}");
        let (v, w) = AGV.body_velocity(l, r);
        // Slower, same curvature w / v = 0.5.
        assert!(v < 2.0 && (w / v - 0.5).abs() < 1e-9);
        assert_eq!(AGV.wheel_speeds(1.0, 0.0, 0.0), (0.0, 0.0));
    }

    #[test]
    fn odometry_integrates_lines_and_circles() {
        // 1 m/s straight along 45° for 2 s.
        let mut pose = Pose2D {
            x: 0.0,
            y: 0.0,
            theta: PI / 4.0,
        };
        for _ in 0..200 {
            pose = integrate(pose, 1.0, 0.0, 0.01);
        }
        let d = 2.0 / 2f64.sqrt();
        assert!((pose.x - d).abs() < 1e-9 && (pose.y - d).abs() < 1e-9);
        // A full circle of radius 1 m (1 m/s, 1 rad/s) ends where it started.
        let mut pose = Pose2D::default();
        let steps = 1000;
        for _ in 0..steps {
            pose = integrate(pose, 1.0, 1.0, TAU / steps as f64);
        }
        assert!(pose.x.abs() < 1e-9 && pose.y.abs() < 1e-9, "{pose:?}");
        // Half way round the circle is 2 m to the left.
        let half = integrate(Pose2D::default(), 1.0, 1.0, PI);
        assert!((half.y - 2.0).abs() < 1e-9 && half.x.abs() < 1e-9);
        // Turning on the spot does not move.
        let spin = integrate(Pose2D::default(), 0.0, 2.0, 0.5);
        assert_eq!((spin.x, spin.y), (0.0, 0.0));
        assert!((spin.theta - 1.0).abs() < 1e-12);
    }
}
