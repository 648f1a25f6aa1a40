//! `crash_course.MainSimulation`: kinematics of the robot, its IR sensors and walls.

use crate::Pose2D;
use ferroc_runtime::module::{In, Kind, Module, ModuleType, Out, Parameter, Setup};

/// Simulated time per control step when the module runs outside a periodic thread
/// container (a test calling its steps). In a model it advances by its container's
/// period ([`step_seconds`]), a fixed step rather than wall-clock time, so a run is
/// reproducible cycle for cycle.
pub const STEP_SECONDS: f64 = 0.04;

/// Simulated time per control step: the period of the thread container running the
/// step (the crash course's `main`, 40 ms), else [`STEP_SECONDS`].
pub fn step_seconds() -> f64 {
    ferroc_runtime::module::cycle::period().map_or(STEP_SECONDS, |p| p.as_secs_f64())
}
/// Distance from the robot's centre to its bumper.
const RADIUS: f64 = 0.15;

/// Kinematic simulation of the crash-course robot and its arena.
pub struct MainSimulation {
    pose_out: Out<Pose2D>,
    ir_front: Out<f64>,
    ir_rear: Out<f64>,
    last_collision: Out<Pose2D>,
    robot_counter: Out<u32>,
    velocity: In<f64>,
    angular_velocity: In<f64>,
    destructive_speed: Parameter<f64>,
    max_speed: Parameter<f64>,
    max_turn_deg: Parameter<f64>,
    ir_max_range: Parameter<f64>,
    arena_size: Parameter<f64>,
    pose: Pose2D,
    robots: u32,
}

impl ModuleType for MainSimulation {
    const NAME: &'static str = "crash_course.MainSimulation";
    const KIND: Kind = Kind::SenseControl;
    const DOC: &'static str = "Kinematic simulation of the crash-course robot and its arena";

    fn create(m: &mut Setup<'_>) -> Self {
        MainSimulation {
            pose_out: m
                .sensor_output("pose")
                .doc("true pose of the current robot")
                .build(),
            ir_front: m.sensor_output("ir_distance_front").unit("m").build(),
            ir_rear: m.sensor_output("ir_distance_rear").unit("m").build(),
            last_collision: m.sensor_output("last_collision_pose").build(),
            robot_counter: m.sensor_output("robot_counter").build(),
            velocity: m.controller_input("velocity").unit("m/s").build(),
            angular_velocity: m.controller_input("angular_velocity").unit("deg/s").build(),
            destructive_speed: m
                .param("destructive_collision_speed")
                .unit("m/s")
                .range(0.0, 10.0)
                .default(0.5)
                .build(),
            max_speed: m
                .param("max_speed")
                .unit("m/s")
                .range(0.0, 5.0)
                .default(2.0)
                .build(),
            max_turn_deg: m
                .param("max_angular_velocity")
                .unit("deg/s")
                .range(0.0, 720.0)
                .default(180.0)
                .build(),
            ir_max_range: m
                .param("ir_max_range")
                .unit("m")
                .range(0.1, 10.0)
                .default(2.0)
                .build(),
            arena_size: m
                .param("arena_size")
                .unit("m")
                .range(1.0, 100.0)
                .default(10.0)
                .build(),
            pose: Pose2D::default(),
            robots: 1,
        }
    }
}

impl MainSimulation {
    /// Distance from the robot's bumper to the wall along `heading`.
    fn wall_distance(&mut self, heading: f64) -> f64 {
        let half = self.arena_size.get() / 2.0;
        let d = ray_to_walls(self.pose.x, self.pose.y, heading, half) - RADIUS;
        d.clamp(0.0, self.ir_max_range.get())
    }
}

/// How far a ray from (`x`, `y`) along `heading` (radians) goes before it meets a wall
/// of the square arena reaching `half` metres from the middle each way (infinite for a
/// point outside that never meets one).
pub fn ray_to_walls(x: f64, y: f64, heading: f64, half: f64) -> f64 {
    let along = |p: f64, d: f64| {
        if d > 1e-9 {
            (half - p) / d
        } else if d < -1e-9 {
            (-half - p) / d
        } else {
            f64::INFINITY
        }
    };
    along(x, heading.cos()).min(along(y, heading.sin()))
}

impl Module for MainSimulation {
    fn sense(&mut self) {
        let front = self.wall_distance(self.pose.yaw);
        let rear = self.wall_distance(self.pose.yaw + std::f64::consts::PI);
        self.pose_out.publish(self.pose);
        self.ir_front.publish(front);
        self.ir_rear.publish(rear);
        self.robot_counter.publish(self.robots);
    }

    fn control(&mut self) {
        let max = self.max_speed.get();
        let speed = self.velocity.get().clamp(-max, max);
        let max_turn = self.max_turn_deg.get().to_radians();
        let turn = self
            .angular_velocity
            .get()
            .to_radians()
            .clamp(-max_turn, max_turn);
        let dt = step_seconds();
        self.pose.yaw = (self.pose.yaw + turn * dt).rem_euclid(std::f64::consts::TAU);
        let half = self.arena_size.get() / 2.0 - RADIUS;
        let x = self.pose.x + speed * self.pose.yaw.cos() * dt;
        let y = self.pose.y + speed * self.pose.yaw.sin() * dt;
        if x.abs() <= half && y.abs() <= half {
            self.pose.x = x;
            self.pose.y = y;
            return;
        }
        // A wall: stop there; too fast and the robot is destroyed.
        self.pose.x = x.clamp(-half, half);
        self.pose.y = y.clamp(-half, half);
        if speed.abs() > self.destructive_speed.get() {
            self.last_collision.publish(self.pose);
            self.robots += 1;
            // The next robot starts in the middle, facing a new direction.
            self.pose = Pose2D {
                x: 0.0,
                y: 0.0,
                yaw: (self.robots as f64 * 2.4).rem_euclid(std::f64::consts::TAU),
            };
        }
    }
}
