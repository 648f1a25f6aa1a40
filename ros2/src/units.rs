//! The units ROS 2 messages carry by convention (REP-103, "Standard Units of Measure and
//! Coordinate Conventions": SI units, `m`, `rad`, `m/s`, `rad/s`, `s`), per field of the
//! shipped message types whose fields have a fixed meaning. The `.msg` files of
//! geometry_msgs state none of these in a form rosidl reads, so they are tabulated here
//! from REP-103 and the message comments.
//!
//! A convention holds for the field's whole subtree: `Twist.linear` is `m/s`, so
//! `Twist.linear.x` is too. Where a field of a nested message has its own entry, the
//! innermost one applies (`Pose.position` is `m` inside `Odometry.pose.pose`).

/// `(message type, field, unit)`.
const CONVENTIONS: &[(&str, &str, &str)] = &[
    ("geometry_msgs/msg/Twist", "linear", "m/s"),
    ("geometry_msgs/msg/Twist", "angular", "rad/s"),
    ("geometry_msgs/msg/Accel", "linear", "m/s^2"),
    ("geometry_msgs/msg/Accel", "angular", "rad/s^2"),
    ("geometry_msgs/msg/Pose", "position", "m"),
    ("geometry_msgs/msg/Pose2D", "x", "m"),
    ("geometry_msgs/msg/Pose2D", "y", "m"),
    ("geometry_msgs/msg/Pose2D", "theta", "rad"),
    ("geometry_msgs/msg/Transform", "translation", "m"),
    ("sensor_msgs/msg/Imu", "angular_velocity", "rad/s"),
    ("sensor_msgs/msg/Imu", "linear_acceleration", "m/s^2"),
    ("sensor_msgs/msg/LaserScan", "angle_min", "rad"),
    ("sensor_msgs/msg/LaserScan", "angle_max", "rad"),
    ("sensor_msgs/msg/LaserScan", "angle_increment", "rad"),
    ("sensor_msgs/msg/LaserScan", "time_increment", "s"),
    ("sensor_msgs/msg/LaserScan", "scan_time", "s"),
    ("sensor_msgs/msg/LaserScan", "range_min", "m"),
    ("sensor_msgs/msg/LaserScan", "range_max", "m"),
    ("sensor_msgs/msg/LaserScan", "ranges", "m"),
    ("sensor_msgs/msg/Range", "field_of_view", "rad"),
    ("sensor_msgs/msg/Range", "min_range", "m"),
    ("sensor_msgs/msg/Range", "max_range", "m"),
    ("sensor_msgs/msg/Range", "range", "m"),
    ("sensor_msgs/msg/NavSatFix", "latitude", "deg"),
    ("sensor_msgs/msg/NavSatFix", "longitude", "deg"),
    ("sensor_msgs/msg/NavSatFix", "altitude", "m"),
    ("nav_msgs/msg/MapMetaData", "resolution", "m"),
    ("builtin_interfaces/msg/Time", "sec", "s"),
    ("builtin_interfaces/msg/Time", "nanosec", "ns"),
    ("builtin_interfaces/msg/Duration", "sec", "s"),
    ("builtin_interfaces/msg/Duration", "nanosec", "ns"),
];

/// The conventional unit of `field` of `message` (`pkg/msg/Name`), if REP-103 fixes one.
pub fn convention(message: &str, field: &str) -> Option<&'static str> {
    CONVENTIONS
        .iter()
        .find(|(m, f, _)| *m == message && *f == field)
        .map(|(_, _, u)| *u)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::def::TypeName;
    use crate::Registry;

    #[test]
    fn every_convention_names_a_shipped_field() {
        let reg = Registry::shipped();
        for (m, f, _) in CONVENTIONS {
            let msg = reg
                .message(&TypeName::parse(m).unwrap())
                .unwrap_or_else(|| panic!("{m} is not shipped"));
            assert!(msg.fields.iter().any(|x| x.name == *f), "{m} has no {f}");
        }
        assert_eq!(convention("geometry_msgs/msg/Twist", "linear"), Some("m/s"));
        assert_eq!(convention("geometry_msgs/msg/Twist", "x"), None);
    }
}
