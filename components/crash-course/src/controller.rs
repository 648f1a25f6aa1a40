//! `crash_course.Controller`: look around, then drive only where the walls are not.
//!
//! It repeats three phases: turn in place half a turn while both rays sample the walls
//! around (`Scan`), turn to the heading whose corridor is free farthest (`Turn`, see
//! `plan.rs`), drive straight that far (`Drive`), stopping early when the front ray
//! unexpectedly sees something close. It never moves sideways into a wall it has not
//! seen, and one noisy reading cannot send it into one.
//!
//! Given a goal (`goal`, a `geometry_msgs/msg/PoseStamped` in the arena's frame `odom`,
//! e.g. from rviz2's "2D Goal Pose" as `/goal_pose`), it turns to the goal's x/y and
//! drives there instead, at most `MAX_DRIVE` at a time, and stands at it until the next
//! goal; the goal's orientation is not used. A drive the front ray finds blocked drops
//! the goal, and the robot looks around as before.

use crate::plan::{self, Reading};
use crate::ros::PoseStamped;
use crate::Pose2D;
use ferroc_runtime::module::{In, Kind, Module, ModuleType, Out, Parameter, Setup};

/// The robot's body: distance from its centre to the bumper (the simulation's too).
const BODY_RADIUS: f64 = 0.15;
/// The longest straight drive (what the rays saw limits it first).
const MAX_DRIVE: f64 = 2.0;
/// Turning: angular velocity per radian still to turn (1/s), below `max_angular_velocity`.
const TURN_GAIN: f64 = 10.0;
/// Driving: velocity per metre still to go (1/s), below `max_velocity`.
const DRIVE_GAIN: f64 = 2.0;
/// A heading this close (radians) is reached; a drive this close (metres) is done.
const HEADING_TOLERANCE: f64 = 0.01;
const DISTANCE_TOLERANCE: f64 = 0.01;
/// A goal this close (metres) is reached.
const GOAL_TOLERANCE: f64 = 0.1;

/// What the controller is doing.
#[derive(Clone, Debug)]
enum Phase {
    /// Turning in place and sampling; `turned` radians so far.
    Scan { turned: f64, readings: Vec<Reading> },
    /// Turning in place to the heading of the drive.
    Turn(plan::Drive),
    /// Driving straight from `from`.
    Drive {
        drive: plan::Drive,
        from: (f64, f64),
    },
}

/// Wall-avoiding controller of the crash-course robot.
pub struct Controller {
    pose: In<Pose2D>,
    ir_front: In<f64>,
    ir_rear: In<f64>,
    obstacle_distance: Out<f64>,
    enable: In<bool>,
    goal_in: In<PoseStamped>,
    velocity: Out<f64>,
    angular_velocity: Out<f64>,
    safety_distance: Parameter<f64>,
    max_velocity: Parameter<f64>,
    max_angular_velocity: Parameter<f64>,
    turn_direction: Parameter<String>,
    front: f64,
    rear: f64,
    /// Where the robot was when `front` and `rear` were read.
    at: Pose2D,
    /// The last three front readings, newest last (a median outvotes one bad reading).
    recent_front: [f64; 3],
    phase: Phase,
    /// `enable` counts only once something was published to it; unconnected, drive.
    enable_seen: bool,
    /// Where to drive to (x, y in the arena's frame), once a goal came.
    goal: Option<(f64, f64)>,
}

impl ModuleType for Controller {
    const NAME: &'static str = "crash_course.Controller";
    const KIND: Kind = Kind::SenseControl;
    const DOC: &'static str = "Wall-avoiding controller of the crash-course robot: looks around, then drives where it is free";

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
            goal_in: m
                .controller_input("goal")
                .doc("drive to its x/y (in odom) and stand there")
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
                .doc("clearance kept between the body and anything the sensors saw")
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
                .doc("the way it turns while looking around")
                .build(),
            front: f64::INFINITY,
            rear: f64::INFINITY,
            at: Pose2D::default(),
            recent_front: [f64::INFINITY; 3],
            phase: Phase::scan(),
            enable_seen: false,
            goal: None,
        }
    }
}

impl Phase {
    fn scan() -> Phase {
        Phase::Scan {
            turned: 0.0,
            readings: Vec::with_capacity(160),
        }
    }
}

impl Controller {
    /// Velocity and angular velocity for this cycle; moves on to the next phase.
    fn step(&mut self) -> (f64, f64) {
        let max_v = self.max_velocity.get();
        let max_w = self.max_angular_velocity.get();
        let safety = self.safety_distance.get();
        let sign = if self.turn_direction.value() == "right" {
            -1.0
        } else {
            1.0
        };
        let at = self.at;
        let steer = |heading: f64| (TURN_GAIN * plan::wrap(heading - at.yaw)).clamp(-max_w, max_w);
        if let (Some(goal), Phase::Scan { .. }) = (self.goal, &self.phase) {
            match plan::toward(goal, (at.x, at.y), GOAL_TOLERANCE, MAX_DRIVE) {
                Some(drive) => self.phase = Phase::Turn(drive),
                // There: stand.
                None => return (0.0, 0.0),
            }
        }
        match &mut self.phase {
            Phase::Scan { turned, readings } => {
                readings.push(Reading {
                    heading: at.yaw,
                    range: self.front,
                });
                readings.push(Reading {
                    heading: at.yaw + std::f64::consts::PI,
                    range: self.rear,
                });
                if let Some(previous) = readings.len().checked_sub(4).map(|i| readings[i].heading) {
                    *turned += plan::wrap(at.yaw - previous).abs();
                }
                // Half a turn and one reading more: the rear ray covered the other half.
                if *turned > std::f64::consts::PI {
                    let drive = plan::choose(readings, BODY_RADIUS + safety, MAX_DRIVE);
                    self.phase = Phase::Turn(drive);
                    return self.step();
                }
                (0.0, sign * max_w)
            }
            Phase::Turn(drive) => {
                let drive = *drive;
                if plan::wrap(drive.heading - at.yaw).abs() > HEADING_TOLERANCE {
                    return (0.0, steer(drive.heading));
                }
                self.phase = Phase::Drive {
                    drive,
                    from: (at.x, at.y),
                };
                self.step()
            }
            Phase::Drive { drive, from } => {
                let travelled = (at.x - from.0).hypot(at.y - from.1);
                let left = drive.distance - travelled;
                let mut recent = self.recent_front;
                recent.sort_by(f64::total_cmp);
                // The corridor was free: something close ahead now is unexpected (and
                // the way to a goal blocked).
                let blocked = recent[1] < safety / 2.0;
                if blocked {
                    self.goal = None;
                }
                if left < DISTANCE_TOLERANCE || blocked {
                    self.phase = Phase::scan();
                    return self.step();
                }
                ((DRIVE_GAIN * left).min(max_v), steer(drive.heading))
            }
        }
    }
}

impl Module for Controller {
    fn sense(&mut self) {
        self.front = self.ir_front.get();
        self.rear = self.ir_rear.get();
        self.at = self.pose.get();
        self.recent_front = [self.recent_front[1], self.recent_front[2], self.front];
        self.obstacle_distance.publish(self.front.min(self.rear));
    }

    fn control(&mut self) {
        self.enable_seen |= self.enable.changed();
        if self.goal_in.changed() {
            let goal = self.goal_in.get();
            self.goal = Some((goal.pose.position.x, goal.pose.position.y));
            // Head for it now, from wherever the robot is.
            self.phase = Phase::scan();
        }
        let enabled = !self.enable_seen || *self.enable.get();
        let (v, w) = if enabled {
            self.step()
        } else {
            // Start over with a fresh look once enabled again.
            self.phase = Phase::scan();
            (0.0, 0.0)
        };
        self.velocity.publish(v);
        self.angular_velocity.publish(w);
    }
}
