//! Value types of the shape of ROS 2 messages the demo (models/ros2_demo.xml,
//! docs/ros2.md) publishes and takes: `std_msgs/msg/Header`, `sensor_msgs/msg/LaserScan`,
//! `geometry_msgs/msg/Point`, `Quaternion`, `Pose`, `PoseStamped`,
//! `PoseWithCovariance`, `TwistWithCovariance` and `nav_msgs/msg/Odometry`. Each has the
//! message's fields by name, in its order and with its widths, so check R102 matches
//! them field by field and the CDR is written straight from them.

use crate::Twist;
use ferroc_runtime::module::Timestamp;

/// `std_msgs/msg/Header`: when (`builtin_interfaces/msg/Time`) and in which frame.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Header {
    pub stamp: Timestamp,
    pub frame_id: String,
}

/// `sensor_msgs/msg/LaserScan`: one sweep of a planar range finder (m, rad, s).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LaserScan {
    pub header: Header,
    pub angle_min: f32,
    pub angle_max: f32,
    pub angle_increment: f32,
    pub time_increment: f32,
    pub scan_time: f32,
    pub range_min: f32,
    pub range_max: f32,
    pub ranges: Vec<f32>,
    pub intensities: Vec<f32>,
}

/// `geometry_msgs/msg/Point` (m).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, bytemuck::NoUninit, serde::Serialize, serde::Deserialize,
)]
#[repr(C)]
pub struct Point {
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

/// `geometry_msgs/msg/Quaternion`: an orientation (x, y, z, w).
#[derive(
    Clone, Copy, Debug, PartialEq, bytemuck::NoUninit, serde::Serialize, serde::Deserialize,
)]
#[repr(C)]
pub struct Quaternion {
    pub x: f64,
    pub y: f64,
    pub z: f64,
    pub w: f64,
}

impl Default for Quaternion {
    /// No rotation (the message's default `w = 1`).
    fn default() -> Self {
        Quaternion::from_yaw(0.0)
    }
}

impl Quaternion {
    /// The rotation by `yaw` radians about z (counter-clockwise seen from above).
    pub fn from_yaw(yaw: f64) -> Self {
        let (s, c) = (yaw / 2.0).sin_cos();
        Quaternion {
            x: 0.0,
            y: 0.0,
            z: s,
            w: c,
        }
    }

    /// The rotation about z this quaternion makes (radians, in (−π, π]).
    pub fn yaw(&self) -> f64 {
        let siny = 2.0 * (self.w * self.z + self.x * self.y);
        let cosy = 1.0 - 2.0 * (self.y * self.y + self.z * self.z);
        siny.atan2(cosy)
    }
}

/// `geometry_msgs/msg/Pose`: a position and an orientation.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, bytemuck::NoUninit, serde::Serialize, serde::Deserialize,
)]
#[repr(C)]
pub struct Pose {
    pub position: Point,
    pub orientation: Quaternion,
}

/// `geometry_msgs/msg/PoseStamped`: a pose in the header's frame.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PoseStamped {
    pub header: Header,
    pub pose: Pose,
}

/// `geometry_msgs/msg/PoseWithCovariance`: row-major 6×6 covariance of x, y, z and the
/// rotations about x, y, z.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PoseWithCovariance {
    pub pose: Pose,
    #[serde(with = "fixed36")]
    pub covariance: [f64; 36],
}

/// `geometry_msgs/msg/TwistWithCovariance`.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TwistWithCovariance {
    pub twist: Twist,
    #[serde(with = "fixed36")]
    pub covariance: [f64; 36],
}

impl Default for PoseWithCovariance {
    fn default() -> Self {
        PoseWithCovariance {
            pose: Pose::default(),
            covariance: [0.0; 36],
        }
    }
}

impl Default for TwistWithCovariance {
    fn default() -> Self {
        TwistWithCovariance {
            twist: Twist::default(),
            covariance: [0.0; 36],
        }
    }
}

/// `nav_msgs/msg/Odometry`: the pose in `header.frame_id`, the twist in
/// `child_frame_id`.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Odometry {
    pub header: Header,
    pub child_frame_id: String,
    pub pose: PoseWithCovariance,
    pub twist: TwistWithCovariance,
}

/// `geometry_msgs/msg/Transform`: where a child frame is in its parent (m).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, bytemuck::NoUninit, serde::Serialize, serde::Deserialize,
)]
#[repr(C)]
pub struct Transform {
    pub translation: crate::Vector3,
    pub rotation: Quaternion,
}

/// `geometry_msgs/msg/TransformStamped`: `child_frame_id` in `header.frame_id`.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TransformStamped {
    pub header: Header,
    pub child_frame_id: String,
    pub transform: Transform,
}

/// `tf2_msgs/msg/TFMessage`, what `/tf` carries (the model brings its definition:
/// models/interfaces/tf2_msgs).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TfMessage {
    pub transforms: Vec<TransformStamped>,
}

ferroc_runtime::port_value!(Header, "crash_course.Header", pooled);
ferroc_runtime::port_value!(Transform, "crash_course.Transform", copy);
ferroc_runtime::port_value!(TransformStamped, "crash_course.TransformStamped", pooled);
ferroc_runtime::port_value!(TfMessage, "crash_course.TFMessage", pooled);
ferroc_runtime::port_value!(LaserScan, "crash_course.LaserScan", pooled);
ferroc_runtime::port_value!(Point, "crash_course.Point", copy);
ferroc_runtime::port_value!(Quaternion, "crash_course.Quaternion", copy);
ferroc_runtime::port_value!(Pose, "crash_course.Pose", copy);
ferroc_runtime::port_value!(PoseStamped, "crash_course.PoseStamped", pooled);
ferroc_runtime::port_value!(
    PoseWithCovariance,
    "crash_course.PoseWithCovariance",
    pooled
);
ferroc_runtime::port_value!(
    TwistWithCovariance,
    "crash_course.TwistWithCovariance",
    pooled
);
ferroc_runtime::port_value!(Odometry, "crash_course.Odometry", pooled);

/// serde for `[f64; 36]` (serde's own arrays stop at 32): a tuple of 36, as a fixed
/// array `float64[36]` is on the wire (no length) and a list in JSON.
mod fixed36 {
    use serde::de::{Error, SeqAccess, Visitor};
    use serde::ser::SerializeTuple;
    use serde::{Deserializer, Serializer};
    use std::fmt;

    pub fn serialize<S: Serializer>(values: &[f64; 36], s: S) -> Result<S::Ok, S::Error> {
        let mut t = s.serialize_tuple(36)?;
        for v in values {
            t.serialize_element(v)?;
        }
        t.end()
    }

    struct Values;

    impl<'de> Visitor<'de> for Values {
        type Value = [f64; 36];

        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str("36 numbers")
        }

        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<[f64; 36], A::Error> {
            let mut out = [0.0; 36];
            for (i, slot) in out.iter_mut().enumerate() {
                *slot = seq
                    .next_element()?
                    .ok_or_else(|| A::Error::invalid_length(i, &self))?;
            }
            if seq.next_element::<f64>()?.is_some() {
                return Err(A::Error::invalid_length(37, &self));
            }
            Ok(out)
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 36], D::Error> {
        d.deserialize_tuple(36, Values)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_quaternion_from_yaw_turns_about_z_and_back() {
        for yaw in [0.0, 0.5, -2.0, 3.0] {
            let q = Quaternion::from_yaw(yaw);
            assert!((q.x, q.y) == (0.0, 0.0));
            assert!((q.z * q.z + q.w * q.w - 1.0).abs() < 1e-12);
            assert!((q.yaw() - yaw).abs() < 1e-12, "{yaw}: {q:?}");
        }
        assert_eq!(Quaternion::default().w, 1.0);
    }

    /// `value` as the CDR of `message` and back, as a ROS 2 end writes and reads it.
    fn through_cdr<T>(message: &str, value: &T) -> T
    where
        T: serde::Serialize + serde::de::DeserializeOwned,
    {
        use ferroc_ros2::def::TypeName;
        use ferroc_ros2::serde_cdr::{self, Shape};
        let reg = ferroc_ros2::Registry::shipped();
        let shape = Shape::new(&reg, &TypeName::parse(message).unwrap(), None).unwrap();
        let bytes = serde_cdr::encode(&shape, value).unwrap_or_else(|e| panic!("{message}: {e}"));
        serde_cdr::from_cdr(&shape, &bytes).unwrap_or_else(|e| panic!("{message}: {e}"))
    }

    #[test]
    fn the_demo_s_messages_cross_as_their_ros2_messages_cdr() {
        let header = Header {
            stamp: Timestamp {
                nanos: 1_700_000_000_123_456_789,
            },
            frame_id: "base_link".into(),
        };
        let scan = LaserScan {
            header: header.clone(),
            angle_min: -3.1,
            angle_max: 3.1,
            angle_increment: 0.0175,
            scan_time: 0.04,
            range_min: 0.05,
            range_max: 12.0,
            ranges: vec![1.0, 2.5, f32::INFINITY],
            ..LaserScan::default()
        };
        assert_eq!(through_cdr("sensor_msgs/msg/LaserScan", &scan), scan);
        let mut odom = Odometry {
            header: header.clone(),
            child_frame_id: "base_link".into(),
            ..Odometry::default()
        };
        odom.pose.pose.position.x = 1.5;
        odom.pose.pose.orientation = Quaternion::from_yaw(0.7);
        odom.pose.covariance[7] = 0.25;
        odom.twist.twist.angular.z = -0.5;
        odom.twist.covariance[35] = 0.125;
        assert_eq!(through_cdr("nav_msgs/msg/Odometry", &odom), odom);
        let goal = PoseStamped {
            header,
            pose: Pose::default(),
        };
        assert_eq!(through_cdr("geometry_msgs/msg/PoseStamped", &goal), goal);
    }

    #[test]
    fn odometry_s_serde_form_has_the_message_s_field_names_and_36_covariances() {
        let mut odom = Odometry {
            child_frame_id: "base_link".into(),
            ..Odometry::default()
        };
        odom.pose.covariance[35] = 0.5;
        let json = serde_json::to_value(&odom).unwrap();
        let mut keys: Vec<&String> = json.as_object().unwrap().keys().collect();
        keys.sort();
        assert_eq!(keys, ["child_frame_id", "header", "pose", "twist"]);
        let covariance = json["pose"]["covariance"].as_array().unwrap();
        assert_eq!(covariance.len(), 36);
        assert_eq!(covariance[35], 0.5);
        assert_eq!(json["pose"]["pose"]["orientation"]["w"], 1.0);
        let back: Odometry = serde_json::from_value(json).unwrap();
        assert_eq!(back, odom);
        // 35 or 37 numbers are not a covariance.
        let mut short = serde_json::to_value(&odom).unwrap();
        short["twist"]["covariance"].as_array_mut().unwrap().pop();
        assert!(serde_json::from_value::<Odometry>(short).is_err());
        let mut long = serde_json::to_value(&odom).unwrap();
        long["twist"]["covariance"]
            .as_array_mut()
            .unwrap()
            .push(0.0.into());
        assert!(serde_json::from_value::<Odometry>(long).is_err());
    }
}
