//! `rescue.LaserDriver` and `rescue.BaseDriver`: the robot's range finder and its
//! differential-drive base, talking to the simulated hardware ([`crate::hardware`]).

use crate::hardware::{robot, Robot, PHYSICS_STEP};
use crate::types::{LaserScan, Pose2D};
use ferroc_runtime::module::{In, Kind, Module, ModuleType, Out, Parameter, Setup};
use std::time::Duration;

/// Beams per sweep: 1° apart over the front half-circle.
pub const BEAMS: usize = 181;
/// Reflectivity the walls return.
const WALL_INTENSITY: f32 = 0.8;

/// Measures one sweep from `pose` (beams from -90° to +90° of the heading). A beam
/// without a return within `max_range` reads +∞ with intensity 0 (REP 117), not the
/// maximum range: a ring of maximum-range points would look like walls.
pub fn sweep(robot: &Robot, pose: &Pose2D, max_range: f64, stamp: Duration) -> LaserScan {
    let angle_increment = std::f64::consts::PI / (BEAMS - 1) as f64;
    let angle_min = -std::f64::consts::FRAC_PI_2;
    let mut scan = LaserScan {
        stamp,
        angle_min,
        angle_increment,
        ranges: Vec::with_capacity(BEAMS),
        intensities: Vec::with_capacity(BEAMS),
    };
    for i in 0..BEAMS {
        let angle = pose.theta + angle_min + angle_increment * i as f64;
        let range = robot.world.ray((pose.x, pose.y), angle, max_range);
        let hit = range < max_range;
        scan.ranges
            .push(if hit { range as f32 } else { f32::INFINITY });
        scan.intensities
            .push(if hit { WALL_INTENSITY } else { 0.0 });
    }
    scan
}

/// Publishes a scan at the configured rate, measured `latency` before it is read.
pub struct LaserDriver {
    scan: Out<LaserScan>,
    #[allow(dead_code)] // names the serial device; the simulation needs none
    device: Parameter<String>,
    rate: Parameter<f64>,
    max_range: Parameter<f64>,
    latency: Parameter<f64>,
    /// Model time of the next sweep.
    next: Duration,
}

impl ModuleType for LaserDriver {
    const NAME: &'static str = "rescue.LaserDriver";
    const DOC: &'static str = "Driver for a serial planar laser range finder";

    fn create(m: &mut Setup<'_>) -> Self {
        LaserDriver {
            scan: m.output("scan").build(),
            device: m
                .param("device")
                .doc("serial device, e.g. /dev/ttyUSB0")
                .build(),
            rate: m
                .param("rate")
                .unit("Hz")
                .range(1.0, 75.0)
                .default(10.0)
                .doc("scan rate; may be changed at run time (context switching)")
                .build(),
            max_range: m
                .param("max_range")
                .unit("m")
                .range(0.1, 80.0)
                .default(30.0)
                .build(),
            latency: m
                .param("latency")
                .unit("ms")
                .range(0.0, 100.0)
                .default(5.0)
                .doc("time between measurement and reception, subtracted from the stamp")
                .build(),
            next: Duration::ZERO,
        }
    }
}

impl Module for LaserDriver {
    fn update(&mut self) {
        let robot = robot();
        if robot.time < self.next {
            return;
        }
        // The range is enforced by the runtime; `max` keeps a zero rate out anyway.
        let period = Duration::from_secs_f64(1.0 / self.rate.get().max(1.0));
        self.next = robot.time + period;
        let latency = Duration::from_secs_f64(self.latency.get().max(0.0) / 1000.0);
        let pose = robot.pose_ago(latency);
        let stamp = robot.time.saturating_sub(latency);
        let scan = sweep(&robot, &pose, self.max_range.get(), stamp);
        drop(robot);
        self.scan.publish(scan);
    }
}

/// The motor board: odometry, battery and bumper in the sense step; wheel commands,
/// limited and watched, in the control step.
pub struct BaseDriver {
    odometry: Out<Pose2D>,
    battery_voltage: Out<f64>,
    bumper: Out<bool>,
    velocity: In<f64>,
    angular_velocity: In<f64>,
    #[allow(dead_code)] // names the motor board's port; the simulation needs none
    port: Parameter<String>,
    max_speed: Parameter<f64>,
    max_turn_rate: Parameter<f64>,
    wheel_base: Parameter<f64>,
    watchdog: Parameter<Duration>,
    /// Model time of the last command.
    last_command: Duration,
}

impl ModuleType for BaseDriver {
    const NAME: &'static str = "rescue.BaseDriver";
    const KIND: Kind = Kind::SenseControl;
    const DOC: &'static str = "Differential-drive base with odometry, bumpers and power board";

    fn create(m: &mut Setup<'_>) -> Self {
        BaseDriver {
            odometry: m.sensor_output("odometry").build(),
            battery_voltage: m.sensor_output("battery_voltage").unit("V").build(),
            bumper: m.sensor_output("bumper").build(),
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
            port: m
                .param("port")
                .doc("CAN or serial port of the motor board")
                .build(),
            max_speed: m
                .param("max_speed")
                .unit("m/s")
                .range(0.0, 1.5)
                .default(0.5)
                .build(),
            max_turn_rate: m
                .param("max_turn_rate")
                .unit("rad/s")
                .range(0.0, 3.2)
                .default(1.5)
                .build(),
            wheel_base: m
                .param("wheel_base")
                .unit("m")
                .range(0.1, 2.0)
                .default(0.4)
                .build(),
            watchdog: m
                .param("watchdog")
                .range(0.01, 5.0)
                .default(Duration::from_millis(200))
                .doc("stop the motors when no command arrived for this long")
                .build(),
            last_command: Duration::ZERO,
        }
    }
}

/// Limits a command to what the wheels can do: each wheel at most `max_speed`, the
/// turn rate at most `max_turn`. Returns the (linear, angular) velocity driven.
pub fn wheel_limits(
    linear: f64,
    angular: f64,
    max_speed: f64,
    max_turn: f64,
    wheel_base: f64,
) -> (f64, f64) {
    let finite = |v: f64| if v.is_finite() { v } else { 0.0 };
    let angular = finite(angular).clamp(-max_turn, max_turn);
    let (left, right) = (
        finite(linear) - angular * wheel_base / 2.0,
        finite(linear) + angular * wheel_base / 2.0,
    );
    // Scale both wheels alike so the curve keeps its shape.
    let fastest = left.abs().max(right.abs());
    let scale = if fastest > max_speed && fastest > 0.0 {
        max_speed / fastest
    } else {
        1.0
    };
    let (left, right) = (left * scale, right * scale);
    ((left + right) / 2.0, (right - left) / wheel_base)
}

impl Module for BaseDriver {
    fn sense(&mut self) {
        let robot = robot();
        let (odometry, battery, bumper) = (robot.odometry, robot.battery, robot.bumper);
        drop(robot);
        self.odometry.publish(odometry);
        self.battery_voltage.publish(battery);
        self.bumper.publish(bumper);
    }

    fn control(&mut self) {
        let mut robot = robot();
        // Read both flags: `changed` clears them.
        let fresh = [self.velocity.changed(), self.angular_velocity.changed()];
        if fresh.contains(&true) {
            self.last_command = robot.time;
        }
        let (mut linear, mut angular) = (self.velocity.get(), self.angular_velocity.get());
        if robot.time.saturating_sub(self.last_command) > self.watchdog.get() {
            (linear, angular) = (0.0, 0.0);
        }
        let (linear, angular) = wheel_limits(
            linear,
            angular,
            self.max_speed.get(),
            self.max_turn_rate.get(),
            self.wheel_base.get(),
        );
        robot.step(linear, angular, PHYSICS_STEP);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sweep_reads_the_walls_around_the_start() {
        let robot = Robot::default();
        let scan = sweep(&robot, &robot.pose, 30.0, Duration::from_millis(7));
        assert_eq!(scan.ranges.len(), BEAMS);
        assert_eq!(scan.stamp, Duration::from_millis(7));
        // Straight ahead (east): the partition 6 m away; left (north) the wall 5 m
        // away; right (south) 5 m.
        assert!((scan.range_at(0.0).unwrap() - 6.0).abs() < 1e-5);
        assert!((scan.range_at(std::f64::consts::FRAC_PI_2).unwrap() - 5.0).abs() < 1e-5);
        assert!((scan.range_at(-std::f64::consts::FRAC_PI_2).unwrap() - 5.0).abs() < 1e-5);
        assert!(scan.intensities.iter().all(|&i| i == WALL_INTENSITY));
        // A short range: nothing is hit, every beam reads +∞ (REP 117).
        let short = sweep(&robot, &robot.pose, 1.0, Duration::ZERO);
        assert!(short.ranges.iter().all(|&r| r == f32::INFINITY));
        assert!(short.intensities.iter().all(|&i| i == 0.0));
    }

    #[test]
    fn wheel_limits_keep_the_curve_and_refuse_nonsense() {
        // Within limits: unchanged.
        let (v, w) = wheel_limits(0.3, 0.5, 0.8, 1.5, 0.42);
        assert!((v - 0.3).abs() < 1e-12 && (w - 0.5).abs() < 1e-12);
        // Too fast: both wheels scaled, the ratio v/w kept.
        let (v, w) = wheel_limits(1.0, 1.0, 0.5, 1.5, 0.4);
        assert!((v / w - 1.0).abs() < 1e-12);
        assert!(
            (v + w * 0.2 - 0.5).abs() < 1e-12,
            "fastest wheel at the limit"
        );
        // Turn rate clamped; NaN stops.
        assert!((wheel_limits(0.0, 9.0, 1.0, 1.5, 0.4).1 - 1.5).abs() < 1e-12);
        assert_eq!(
            wheel_limits(f64::NAN, f64::INFINITY, 1.0, 1.5, 0.4),
            (0.0, 0.0)
        );
    }
}
