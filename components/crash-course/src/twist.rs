//! `crash_course.TwistOut`: the controller's two commands as one velocity command of
//! the shape ROS 2's `geometry_msgs/msg/Twist` has, so a part can publish it as
//! `/cmd_vel` (models/ros2_crash_course.xml, docs/ros2.md).

use ferroc_runtime::module::{In, Module, ModuleType, Out, Setup};

/// Three components (`geometry_msgs/msg/Vector3`'s fields).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, bytemuck::NoUninit, serde::Serialize, serde::Deserialize,
)]
#[repr(C)]
pub struct Vector3 {
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

/// A velocity in free space (`geometry_msgs/msg/Twist`'s fields): m/s and rad/s.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, bytemuck::NoUninit, serde::Serialize, serde::Deserialize,
)]
#[repr(C)]
pub struct Twist {
    pub linear: Vector3,
    pub angular: Vector3,
}

ferroc_runtime::port_value!(Vector3, "crash_course.Vector3", copy);
ferroc_runtime::port_value!(Twist, "crash_course.Twist", copy);

/// Packs a forward speed and a turn rate into a [`Twist`] (`linear.x`, `angular.z`).
pub struct TwistOut {
    velocity: In<f64>,
    angular_velocity: In<f64>,
    twist: Out<Twist>,
}

impl ModuleType for TwistOut {
    const NAME: &'static str = "crash_course.TwistOut";
    const DOC: &'static str = "Packs forward speed and turn rate into a Twist";

    fn create(m: &mut Setup<'_>) -> Self {
        TwistOut {
            velocity: m.input("velocity").unit("m/s").build(),
            angular_velocity: m.input("angular_velocity").unit("rad/s").build(),
            twist: m.output("twist").build(),
        }
    }
}

impl Module for TwistOut {
    fn update(&mut self) {
        let mut twist = Twist::default();
        twist.linear.x = self.velocity.get();
        twist.angular.z = self.angular_velocity.get();
        self.twist.publish(twist);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn its_serde_form_has_twists_field_names() {
        let mut t = Twist::default();
        t.linear.x = 0.3;
        t.angular.z = -1.2;
        let json = serde_json::to_value(t).unwrap();
        assert_eq!(
            json,
            serde_json::json!({"linear": {"x": 0.3, "y": 0.0, "z": 0.0},
                               "angular": {"x": 0.0, "y": 0.0, "z": -1.2}})
        );
    }
}
