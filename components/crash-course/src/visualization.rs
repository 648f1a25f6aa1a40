//! `crash_course.Visualization`: what the user watches, as text at a human rate.

use crate::Pose2D;
use ferroc_runtime::console;
use ferroc_runtime::module::{In, Module, ModuleType, Parameter, Setup};

/// Reports the robot once a second and every destroyed robot at once.
pub struct Visualization {
    pose: In<Pose2D>,
    ir_front: In<f64>,
    ir_rear: In<f64>,
    last_collision: In<Pose2D>,
    robot_counter: In<u64>,
    window_title: Parameter<String>,
    #[allow(dead_code)] // a graphical front end would use it; the text view does not
    scale: Parameter<f64>,
    updates: u64,
    robots_seen: u64,
}

impl ModuleType for Visualization {
    const NAME: &'static str = "crash_course.Visualization";
    const DOC: &'static str = "Draws the arena, the robot, its IR beams and the last collision";

    fn create(m: &mut Setup<'_>) -> Self {
        Visualization {
            pose: m.input("pose").build(),
            ir_front: m.input("ir_distance_front").unit("cm").build(),
            ir_rear: m.input("ir_distance_rear").unit("cm").build(),
            last_collision: m.input("last_collision_pose").build(),
            robot_counter: m.input("robot_counter").build(),
            window_title: m
                .param("window_title")
                .default("crash course".to_string())
                .build(),
            scale: m
                .param("scale")
                .range(1.0, 1000.0)
                .default(50.0)
                .doc("pixels per metre")
                .build(),
            updates: 0,
            robots_seen: 1,
        }
    }
}

impl Module for Visualization {
    fn update(&mut self) {
        self.updates += 1;
        let robots = self.robot_counter.get();
        if robots > self.robots_seen {
            let at = self.last_collision.get();
            console::line(&format!(
                "[{}] collision: robot {} destroyed at x={:+.2} m y={:+.2} m",
                self.window_title.value(),
                robots - 1,
                at.x,
                at.y
            ));
            self.robots_seen = robots;
        }
        // Nothing to show before the simulation published its first robot.
        if robots > 0 && self.updates % 10 == 1 {
            let p = self.pose.get();
            console::line(&format!(
                "[{}] robot {robots}: x={:+.2} m y={:+.2} m heading={:>5.1}° front={:>5.1} cm rear={:>5.1} cm",
                self.window_title.value(),
                p.x,
                p.y,
                p.yaw.to_degrees(),
                self.ir_front.get(),
                self.ir_rear.get()
            ));
        }
    }
}
