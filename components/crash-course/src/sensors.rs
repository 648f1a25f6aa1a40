//! What the demo (models/ros2_demo.xml, docs/ros2.md) publishes to ROS 2 besides
//! `/cmd_vel`: `crash_course.LaserScanner`, a simulated planar laser range finder
//! sweeping the arena's walls (`/scan`), and `crash_course.OdometryOut`, the simulated
//! pose and the commanded velocities as odometry (`/odom`). Both stamp their messages
//! with `Timestamp::now()`: model time in a lockstep run.

use crate::ros::{Header, LaserScan, Odometry, Pose, Quaternion, TfMessage, TransformStamped};
use crate::simulation::ray_to_walls;
use crate::{Point, Pose2D};
use ferroc_runtime::module::{In, Module, ModuleType, Out, Parameter, Setup, Timestamp};
use std::f64::consts::{PI, TAU};

/// The frame the robot's sensors measure in (REP-105).
pub const BASE_FRAME: &str = "base_link";
/// The frame odometry places the robot in: the arena's.
pub const ODOM_FRAME: &str = "odom";
/// The closest range the scanner reports (m); the robot's body keeps walls farther.
const RANGE_MIN: f64 = 0.05;

/// A laser scan of the arena from the robot's pose: `rays` rays, counter-clockwise
/// from straight behind (−π) through straight ahead (0), in the robot's frame.
pub struct LaserScanner {
    pose: In<Pose2D>,
    scan: Out<LaserScan>,
    arena_size: Parameter<f64>,
    range_max: Parameter<f64>,
    rays: Parameter<u32>,
}

impl ModuleType for LaserScanner {
    const NAME: &'static str = "crash_course.LaserScanner";
    const DOC: &'static str = "Simulated planar laser scanner: the ranges to the arena's walls";

    fn create(m: &mut Setup<'_>) -> Self {
        LaserScanner {
            pose: m.input("pose").doc("where the scanner is").build(),
            scan: m.output("scan").doc("one sweep, in base_link").build(),
            arena_size: m
                .param("arena_size")
                .unit("m")
                .range(1.0, 100.0)
                .default(10.0)
                .build(),
            range_max: m
                .param("range_max")
                .unit("m")
                .range(1.0, 200.0)
                .default(30.0)
                .doc("farther walls read +inf (REP-117)")
                .build(),
            rays: m
                .param("rays")
                .range(4.0, 4096.0)
                .default(360)
                .doc("rays per sweep, all around")
                .build(),
        }
    }
}

/// The ranges from `pose` in an arena of half-size `half`: `rays` rays from −π on,
/// `RANGE_MIN..=range_max`, +inf where no wall is within `range_max` (REP-117).
pub fn sweep(pose: Pose2D, half: f64, rays: usize, range_max: f64, out: &mut Vec<f32>) {
    let increment = TAU / rays as f64;
    out.clear();
    out.extend((0..rays).map(|i| {
        let bearing = -PI + increment * i as f64;
        let range = ray_to_walls(pose.x, pose.y, pose.yaw + bearing, half);
        if range > range_max {
            f32::INFINITY
        } else {
            range.max(RANGE_MIN) as f32
        }
    }));
}

impl Module for LaserScanner {
    fn update(&mut self) {
        let pose = self.pose.get();
        let half = self.arena_size.get() / 2.0;
        let range_max = self.range_max.get();
        let rays = self.rays.get() as usize;
        let scan_time = crate::simulation::step_seconds();
        let stamp = Timestamp::now();
        self.scan.publish_with(|scan| {
            let increment = TAU / rays as f64;
            scan.header.stamp = stamp;
            scan.header.frame_id.clear();
            scan.header.frame_id.push_str(BASE_FRAME);
            scan.angle_min = -PI as f32;
            scan.angle_max = (-PI + increment * (rays - 1) as f64) as f32;
            scan.angle_increment = increment as f32;
            // The simulation measures every ray at once.
            scan.time_increment = 0.0;
            scan.scan_time = scan_time as f32;
            scan.range_min = RANGE_MIN as f32;
            scan.range_max = range_max as f32;
            sweep(pose, half, rays, range_max, &mut scan.ranges);
            scan.intensities.clear();
        });
    }
}

/// The robot's pose in `odom` and its commanded velocities in `base_link`, as
/// `nav_msgs/msg/Odometry` (covariances zero: unknown), and the same pose as the
/// transform `odom` → `base_link` (`tf2_msgs/msg/TFMessage`, for `/tf`).
pub struct OdometryOut {
    pose: In<Pose2D>,
    velocity: In<f64>,
    angular_velocity: In<f64>,
    odom: Out<Odometry>,
    tf: Out<TfMessage>,
}

impl ModuleType for OdometryOut {
    const NAME: &'static str = "crash_course.OdometryOut";
    const DOC: &'static str =
        "The pose and velocities as odometry and as the transform odom → base_link";

    fn create(m: &mut Setup<'_>) -> Self {
        OdometryOut {
            pose: m.input("pose").build(),
            velocity: m.input("velocity").unit("m/s").build(),
            angular_velocity: m.input("angular_velocity").unit("rad/s").build(),
            odom: m.output("odom").build(),
            tf: m.output("tf").doc("odom → base_link").build(),
        }
    }
}

/// The planar `pose` as a ROS pose: z = 0, the yaw as a quaternion.
pub fn pose_of(pose: Pose2D) -> Pose {
    Pose {
        position: Point {
            x: pose.x,
            y: pose.y,
            z: 0.0,
        },
        orientation: Quaternion::from_yaw(pose.yaw),
    }
}

impl Module for OdometryOut {
    fn update(&mut self) {
        let pose = pose_of(self.pose.get());
        let (v, w) = (self.velocity.get(), self.angular_velocity.get());
        let stamp = Timestamp::now();
        self.odom.publish_with(|odom| {
            odom.header = Header {
                stamp,
                frame_id: ODOM_FRAME.into(),
            };
            odom.child_frame_id.clear();
            odom.child_frame_id.push_str(BASE_FRAME);
            odom.pose.pose = pose;
            odom.pose.covariance = [0.0; 36];
            odom.twist.twist = Default::default();
            odom.twist.twist.linear.x = v;
            odom.twist.twist.angular.z = w;
            odom.twist.covariance = [0.0; 36];
        });
        self.tf.publish_with(|tf| {
            tf.transforms.resize_with(1, TransformStamped::default);
            let t = &mut tf.transforms[0];
            t.header.stamp = stamp;
            t.header.frame_id.clear();
            t.header.frame_id.push_str(ODOM_FRAME);
            t.child_frame_id.clear();
            t.child_frame_id.push_str(BASE_FRAME);
            t.transform.translation.x = pose.position.x;
            t.transform.translation.y = pose.position.y;
            t.transform.translation.z = 0.0;
            t.transform.rotation = pose.orientation;
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sweep_from_the_middle_sees_the_walls_around() {
        let mut ranges = Vec::new();
        let pose = Pose2D {
            x: 0.0,
            y: 0.0,
            yaw: 0.0,
        };
        sweep(pose, 4.0, 360, 30.0, &mut ranges);
        assert_eq!(ranges.len(), 360);
        // Ray 0 looks back (−π), ray 180 ahead, 90 to the right, 270 to the left.
        for i in [0, 90, 180, 270] {
            assert!((ranges[i] - 4.0).abs() < 1e-5, "{i}: {}", ranges[i]);
        }
        // Into a corner: the diagonal.
        assert!((ranges[225] - 4.0 * 2f32.sqrt()).abs() < 1e-4);
        assert!(ranges.iter().all(|r| (4.0..=5.66).contains(r)));
    }

    #[test]
    fn a_sweep_turns_with_the_robot_and_marks_far_walls_infinite() {
        let mut ranges = Vec::new();
        // Near the east wall, facing north: the wall is to the right (ray 90).
        let pose = Pose2D {
            x: 3.0,
            y: 0.0,
            yaw: PI / 2.0,
        };
        sweep(pose, 4.0, 360, 30.0, &mut ranges);
        assert!((ranges[90] - 1.0).abs() < 1e-5, "{}", ranges[90]);
        assert!((ranges[270] - 7.0).abs() < 1e-5, "{}", ranges[270]);
        // Only 5 m of range: the west wall is out of it.
        sweep(pose, 4.0, 360, 5.0, &mut ranges);
        assert_eq!(ranges[270], f32::INFINITY);
        assert!((ranges[90] - 1.0).abs() < 1e-5);
    }

    #[test]
    fn an_odometry_pose_carries_the_yaw_as_a_quaternion() {
        let pose = pose_of(Pose2D {
            x: 1.0,
            y: -2.0,
            yaw: 1.0,
        });
        assert_eq!(
            (pose.position.x, pose.position.y, pose.position.z),
            (1.0, -2.0, 0.0)
        );
        assert!((pose.orientation.yaw() - 1.0).abs() < 1e-12);
    }
}
