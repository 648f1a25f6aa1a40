//! The navigation behaviours: goal following, obstacle avoidance, wall following.
//!
//! Each keeps the iB2C conventions the behaviour base checks: activity ≤ activation,
//! derived activities ≤ activity, and target rating 0 only where the activity is fixed
//! by the activation (arrived: the activation; nothing to do: 0).

use crate::{wrap, Pose2D, RangeScan};
use ferroc_runtime::behaviour::{Behaviour, BehaviourOutput};
use ferroc_runtime::module::{In, Out, Parameter, Setup};
use std::f64::consts::PI;

/// Drives towards the goal; target rating = remaining distance (0 on arrival).
pub struct GoToGoal {
    pose: In<Pose2D>,
    goal: In<Pose2D>,
    linear: Out<f64>,
    angular: Out<f64>,
    max_speed: Parameter<f64>,
    tolerance: Parameter<f64>,
}

impl Behaviour for GoToGoal {
    const NAME: &'static str = "nav_behaviours.GoToGoal";
    const DOC: &'static str = "Turns towards the goal and drives to it";
    const DERIVED: &'static [&'static str] = &["arrived"];

    fn create(m: &mut Setup<'_>) -> Self {
        GoToGoal {
            pose: m.input("pose").required().build(),
            goal: m.input("goal").required().build(),
            linear: m.output("linear").unit("m/s").build(),
            angular: m.output("angular").unit("rad/s").build(),
            max_speed: m
                .param("max_speed")
                .unit("m/s")
                .range(0.0, 2.0)
                .default(0.5)
                .build(),
            tolerance: m
                .param("tolerance")
                .unit("m")
                .range(0.01, 1.0)
                .default(0.1)
                .build(),
        }
    }

    fn transfer(&mut self, activation: f64, derived: &mut [f64]) -> BehaviourOutput {
        let (pose, goal) = (self.pose.get(), self.goal.get());
        let (dx, dy) = (goal.x - pose.x, goal.y - pose.y);
        let distance = dx.hypot(dy);
        if distance < self.tolerance.get() {
            // Arrived: hold still with full authority; content.
            self.linear.publish(0.0);
            self.angular.publish(0.0);
            derived[0] = activation;
            return BehaviourOutput {
                activity: activation,
                target_rating: 0.0,
            };
        }
        let error = wrap(dy.atan2(dx) - pose.theta);
        let speed = self.max_speed.get() * error.cos().max(0.0) * (distance / 0.5).min(1.0);
        self.linear.publish(speed);
        self.angular.publish((1.5 * error).clamp(-1.2, 1.2));
        BehaviourOutput {
            activity: activation,
            target_rating: (distance / 5.0).clamp(0.01, 1.0),
        }
    }
}

/// Turns away from close obstacles; `emergency` while one is inside the stop distance.
pub struct AvoidObstacles {
    scan: In<RangeScan>,
    linear: Out<f64>,
    angular: Out<f64>,
    stop_distance: Parameter<f64>,
    slow_distance: Parameter<f64>,
    min_activity: Parameter<f64>,
}

impl Behaviour for AvoidObstacles {
    const NAME: &'static str = "nav_behaviours.AvoidObstacles";
    const DOC: &'static str = "Reactive obstacle avoidance on a range scan";
    const DERIVED: &'static [&'static str] = &["emergency"];

    fn create(m: &mut Setup<'_>) -> Self {
        AvoidObstacles {
            scan: m.input("scan").required().build(),
            linear: m.output("linear").unit("m/s").build(),
            angular: m.output("angular").unit("rad/s").build(),
            stop_distance: m
                .param("stop_distance")
                .unit("m")
                .range(0.05, 2.0)
                .default(0.3)
                .build(),
            slow_distance: m
                .param("slow_distance")
                .unit("m")
                .range(0.1, 5.0)
                .default(1.0)
                .build(),
            min_activity: m
                .param("min_activity")
                .meta(ferroc_runtime::module::MetaType::Activity)
                .default(0.2)
                .doc("activity while an obstacle is merely inside the slow distance")
                .build(),
        }
    }

    fn transfer(&mut self, activation: f64, derived: &mut [f64]) -> BehaviourOutput {
        let scan = self.scan.get();
        let front = scan.min_in(-PI / 3.0, PI / 3.0);
        let left = scan.min_in(PI / 9.0, PI * 5.0 / 9.0);
        let right = scan.min_in(-PI * 5.0 / 9.0, -PI / 9.0);
        let stop = self.stop_distance.get();
        let slow = self.slow_distance.get().max(stop + 1e-3);
        let closeness = ((slow - front) / (slow - stop)).clamp(0.0, 1.0);
        let away = if left >= right { 1.0 } else { -1.0 };
        if front <= stop {
            self.linear.publish(-0.05);
            self.angular.publish(away * 1.0);
            derived[0] = activation;
            return BehaviourOutput {
                activity: activation,
                target_rating: 1.0,
            };
        }
        if closeness == 0.0 {
            self.linear.publish(0.0);
            self.angular.publish(0.0);
            return BehaviourOutput::default();
        }
        let min = self.min_activity.get();
        self.linear.publish(0.15 * (1.0 - closeness));
        self.angular.publish(away * 0.9 * closeness);
        BehaviourOutput {
            activity: activation * (min + (1.0 - min) * closeness),
            target_rating: closeness,
        }
    }
}

/// Follows a wall on one side at a constant distance; active while a wall blocks the
/// way ahead (fully) or runs alongside (partly).
pub struct FollowWall {
    scan: In<RangeScan>,
    linear: Out<f64>,
    angular: Out<f64>,
    side: Parameter<String>,
    distance: Parameter<f64>,
    /// +1: the wall is on the right (turn left to leave it), −1: on the left.
    sign: f64,
}

impl Behaviour for FollowWall {
    const NAME: &'static str = "nav_behaviours.FollowWall";
    const DOC: &'static str = "Follows a wall at a constant distance";

    fn create(m: &mut Setup<'_>) -> Self {
        let mut side: Parameter<String> = m
            .param("side")
            .choices(&["left", "right"])
            .default("right".to_owned())
            .build();
        let sign = if side.value() == "left" { -1.0 } else { 1.0 };
        FollowWall {
            scan: m.input("scan").required().build(),
            linear: m.output("linear").unit("m/s").build(),
            angular: m.output("angular").unit("rad/s").build(),
            side,
            distance: m
                .param("distance")
                .unit("m")
                .range(0.1, 2.0)
                .default(0.5)
                .build(),
            sign,
        }
    }

    fn transfer(&mut self, activation: f64, _derived: &mut [f64]) -> BehaviourOutput {
        if self.side.changed() {
            self.sign = if self.side.value() == "left" {
                -1.0
            } else {
                1.0
            };
        }
        let scan = self.scan.get();
        let distance = self.distance.get();
        let lookahead = 3.0 * distance;
        let front = scan.min_in(-PI / 6.0, PI / 6.0);
        // The wall side: -90° ± 25° for a wall on the right, +90° ± 25° on the left.
        let centre = -self.sign * PI / 2.0;
        let side = scan.min_in(centre - 0.45, centre + 0.45);
        // A wall ahead makes it needed, a wall alongside somewhat (so that it keeps
        // the robot along a wall while the goal direction leads into it).
        let closeness = |d: f64| ((lookahead - d) / (lookahead - distance)).clamp(0.0, 1.0);
        let need = closeness(front).max(0.6 * closeness(side));
        if need == 0.0 {
            self.linear.publish(0.0);
            self.angular.publish(0.0);
            return BehaviourOutput::default();
        }
        // Turn away from the blocked front, towards keeping `distance` on the side.
        let keep = if side < lookahead {
            (distance - side).clamp(-0.5, 0.5)
        } else {
            0.0
        };
        let turn = self.sign * (1.0 * need + 1.5 * keep);
        self.linear.publish(0.25 * (1.0 - 0.6 * need));
        self.angular.publish(turn.clamp(-1.2, 1.2));
        BehaviourOutput {
            activity: activation * need,
            target_rating: need,
        }
    }
}

/// Claims a fixed activity whatever its activation: a deliberate violation of the
/// activity limitation, to test the runtime checks and the `ib2c-violations` policies.
pub struct FaultInjector {
    activity: Parameter<f64>,
}

impl Behaviour for FaultInjector {
    const NAME: &'static str = "nav_behaviours.FaultInjector";
    const DOC: &'static str =
        "Reports a fixed activity whatever its activation (a deliberate iB2C violation, for tests)";

    fn create(m: &mut Setup<'_>) -> Self {
        FaultInjector {
            activity: m
                .param("activity")
                .meta(ferroc_runtime::module::MetaType::Activity)
                .default(1.0)
                .doc("the activity it claims")
                .build(),
        }
    }

    fn transfer(&mut self, _activation: f64, _derived: &mut [f64]) -> BehaviourOutput {
        BehaviourOutput {
            activity: self.activity.get(),
            target_rating: 1.0,
        }
    }
}
