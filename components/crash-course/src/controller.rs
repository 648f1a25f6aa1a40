//! `crash_course.Controller`: drive forward, slow down and turn before walls.

use crate::Pose2D;
use ferroc_runtime::module::{In, Kind, Module, ModuleType, Out, Parameter, Setup};

/// Reactive wall-avoiding controller of the crash-course robot.
pub struct Controller {
    #[allow(dead_code)] // declared by the manifest; this controller is purely reactive
    pose: In<Pose2D>,
    ir_front: In<f64>,
    ir_rear: In<f64>,
    obstacle_distance: Out<f64>,
    enable: In<bool>,
    velocity: Out<f64>,
    angular_velocity: Out<f64>,
    safety_distance: Parameter<f64>,
    max_velocity: Parameter<f64>,
    max_angular_velocity: Parameter<f64>,
    turn_direction: Parameter<String>,
    front: f64,
    rear: f64,
    /// `enable` counts only once something was published to it; unconnected, drive.
    enable_seen: bool,
}

impl ModuleType for Controller {
    const NAME: &'static str = "crash_course.Controller";
    const KIND: Kind = Kind::SenseControl;
    const DOC: &'static str = "Reactive wall-avoiding controller of the crash-course robot";

    fn create(m: &mut Setup<'_>) -> Self {
        Controller {
            pose: m.sensor_input("pose").build(),
            ir_front: m
                .sensor_input("ir_distance_front")
                .unit("m")
                .required()
                .build(),
            ir_rear: m
                .sensor_input("ir_distance_rear")
                .unit("m")
                .required()
                .build(),
            obstacle_distance: m
                .sensor_output("obstacle_distance")
                .unit("m")
                .doc("nearest obstacle, front or rear")
                .build(),
            enable: m
                .controller_input("enable")
                .doc("drive only while true (default true)")
                .build(),
            velocity: m.controller_output("velocity").unit("m/s").build(),
            angular_velocity: m
                .controller_output("angular_velocity")
                .unit("rad/s")
                .build(),
            safety_distance: m
                .param("safety_distance")
                .unit("m")
                .range(0.0, 2.0)
                .default(0.3)
                .doc("start slowing down and turning below this distance")
                .build(),
            max_velocity: m
                .param("max_velocity")
                .unit("m/s")
                .range(0.0, 2.0)
                .default(0.5)
                .build(),
            max_angular_velocity: m
                .param("max_angular_velocity")
                .unit("rad/s")
                .range(0.0, 6.3)
                .default(1.5)
                .build(),
            turn_direction: m
                .param("turn_direction")
                .choices(&["left", "right"])
                .default("left".to_string())
                .build(),
            front: f64::INFINITY,
            rear: f64::INFINITY,
            enable_seen: false,
        }
    }
}

impl Module for Controller {
    fn sense(&mut self) {
        self.front = self.ir_front.get();
        self.rear = self.ir_rear.get();
        self.obstacle_distance.publish(self.front.min(self.rear));
    }

    fn control(&mut self) {
        self.enable_seen |= self.enable.changed();
        let enabled = !self.enable_seen || *self.enable.get();
        let safety = self.safety_distance.get();
        let max_v = self.max_velocity.get();
        let max_w = self.max_angular_velocity.get();
        let sign = if self.turn_direction.value() == "right" {
            -1.0
        } else {
            1.0
        };
        let (v, w) = if !enabled {
            (0.0, 0.0)
        } else if self.front < safety {
            // Closer to the wall: slower, and turning harder.
            let closeness = 1.0 - self.front / safety.max(1e-6);
            (
                max_v * (1.0 - closeness) * 0.3,
                sign * max_w * closeness.max(0.3),
            )
        } else {
            (max_v, 0.0)
        };
        self.velocity.publish(v);
        self.angular_velocity.publish(w);
    }
}
