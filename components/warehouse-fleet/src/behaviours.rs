//! The iB2C behaviours of `warehouse.SafeNavigation`: path following, obstacle
//! avoidance and the fusion of their velocity commands.
//!
//! Both behaviours keep the conventions the behaviour base checks: activity ≤
//! activation, derived activities ≤ activity, target rating 0 only where the activity
//! is fixed (0, or the activation itself), and zero commands while inactive, so that a
//! fusion with no active channel averages to standing still.

use crate::geometry::{PurePursuit, Steering};
use crate::{LaserScan, Pose2D};
use ferroc_runtime::behaviour::{Behaviour, BehaviourOutput};
use ferroc_runtime::module::{In, Out, Parameter, Setup};
use ferroc_std::fusion::PairFusion;
use std::f64::consts::PI;

/// Slowest speed on the final approach, so that the robot arrives (m/s).
const CREEP: f64 = 0.02;
/// Speed per metre left on the final approach (1/s).
const APPROACH_GAIN: f64 = 0.8;
/// Turn-rate limit of path following (rad/s).
const MAX_TURN: f64 = 1.2;
/// A heading error beyond this turns on the spot first.
const TURN_IN_PLACE: f64 = PI / 3.0;
/// Distances normalised by this give the target rating.
const RATING_DISTANCE: f64 = 10.0;

/// Forward and turn velocity of a steering decision, for path following.
pub fn pursue(steer: Steering, max_speed: f64) -> (f64, f64) {
    if steer.heading_error.abs() > TURN_IN_PLACE {
        return (0.0, MAX_TURN.copysign(steer.heading_error));
    }
    let speed = max_speed
        .min(APPROACH_GAIN * steer.remaining)
        .max(CREEP.min(max_speed))
        * steer.heading_error.cos();
    (speed, (speed * steer.curvature).clamp(-MAX_TURN, MAX_TURN))
}

/// Pure-pursuit path following towards the current goal, along the aisle grid.
pub struct FollowPath {
    pose: In<Pose2D>,
    goal: In<Pose2D>,
    velocity: Out<f64>,
    angular_velocity: Out<f64>,
    goal_reached: Out<bool>,
    max_speed: Parameter<f64>,
    lookahead: Parameter<f64>,
    goal_tolerance: Parameter<f64>,
    /// The goal the path leads to (`None` until one arrives).
    target: Option<Pose2D>,
    path: PurePursuit,
}

impl FollowPath {
    fn halt(&self, reached: bool) {
        self.velocity.publish(0.0);
        self.angular_velocity.publish(0.0);
        self.goal_reached.publish(reached);
    }
}

impl Behaviour for FollowPath {
    const NAME: &'static str = "warehouse.FollowPath";
    const DOC: &'static str = "Pure-pursuit path following towards the current goal";
    const DERIVED: &'static [&'static str] = &["final_approach"];

    fn create(m: &mut Setup<'_>) -> Self {
        FollowPath {
            pose: m.input("pose").required().build(),
            goal: m.input("goal").build(),
            velocity: m.output("velocity").unit("m/s").build(),
            angular_velocity: m.output("angular_velocity").unit("rad/s").build(),
            goal_reached: m.output("goal_reached").build(),
            max_speed: m
                .param("max_speed")
                .unit("m/s")
                .range(0.0, 2.0)
                .default(1.0)
                .build(),
            lookahead: m
                .param("lookahead")
                .unit("m")
                .range(0.05, 5.0)
                .default(0.6)
                .build(),
            goal_tolerance: m
                .param("goal_tolerance")
                .unit("m")
                .range(0.005, 1.0)
                .default(0.02)
                .build(),
            target: None,
            path: PurePursuit::default(),
        }
    }

    fn transfer(&mut self, activation: f64, derived: &mut [f64]) -> BehaviourOutput {
        let pose = self.pose.get();
        if self.goal.changed() {
            let goal = self.goal.get();
            // The executor repeats its goal every cycle: plan only for a new one.
            if self.target != Some(goal) {
                self.target = Some(goal);
                self.path = PurePursuit::grid(pose, goal);
            }
        }
        let Some(goal) = self.target else {
            self.halt(false);
            return BehaviourOutput::default();
        };
        if pose.distance_to(&goal) < self.goal_tolerance.get() {
            self.halt(true);
            derived[0] = activation;
            return BehaviourOutput {
                activity: activation,
                target_rating: 0.0,
            };
        }
        self.goal_reached.publish(false);
        let lookahead = self.lookahead.get();
        let steer = self.path.steer(pose, lookahead);
        if activation > 0.0 {
            let (v, w) = pursue(steer, self.max_speed.get());
            self.velocity.publish(v);
            self.angular_velocity.publish(w);
        } else {
            self.halt(false);
        }
        if steer.remaining < lookahead {
            derived[0] = activation;
        }
        BehaviourOutput {
            activity: activation,
            target_rating: (steer.remaining / RATING_DISTANCE).clamp(0.01, 1.0),
        }
    }
}

/// The nearest range among the beams whose direction lies in `[from, to]` radians
/// (infinite if none does; invalid readings are ignored).
pub fn nearest(scan: &LaserScan, from: f64, to: f64) -> f64 {
    let mut best = f64::INFINITY;
    for (i, r) in scan.ranges.iter().enumerate() {
        let angle = scan.angle_min + i as f64 * scan.angle_increment;
        let r = f64::from(*r);
        if (from..=to).contains(&angle) && r.is_finite() && r >= 0.0 && r < best {
            best = r;
        }
    }
    best
}

/// Reactive obstacle avoidance: slower and turning away as obstacles ahead come
/// closer; `emergency` (stop and turn away) inside the stop distance.
pub struct AvoidObstacles {
    scan: In<LaserScan>,
    velocity: Out<f64>,
    angular_velocity: Out<f64>,
    stop_distance: Parameter<f64>,
    slow_distance: Parameter<f64>,
    creep_speed: Parameter<f64>,
}

impl Behaviour for AvoidObstacles {
    const NAME: &'static str = "warehouse.AvoidObstacles";
    const DOC: &'static str = "Reactive obstacle avoidance on a laser scan";
    const DERIVED: &'static [&'static str] = &["emergency"];

    fn create(m: &mut Setup<'_>) -> Self {
        AvoidObstacles {
            scan: m.input("scan").required().build(),
            velocity: m.output("velocity").unit("m/s").build(),
            angular_velocity: m.output("angular_velocity").unit("rad/s").build(),
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
            creep_speed: m
                .param("creep_speed")
                .unit("m/s")
                .range(0.0, 0.5)
                .default(0.05)
                .build(),
        }
    }

    fn transfer(&mut self, activation: f64, derived: &mut [f64]) -> BehaviourOutput {
        let scan = self.scan.get();
        let limits = Distances {
            stop: self.stop_distance.get(),
            slow: self.slow_distance.get(),
            creep: self.creep_speed.get(),
        };
        let r = avoid(&scan, &limits, activation);
        self.velocity.publish(r.velocity);
        self.angular_velocity.publish(r.angular);
        derived[0] = r.emergency;
        r.output
    }
}

/// What obstacle avoidance reacts to (parameters of `AvoidObstacles`).
#[derive(Clone, Copy, Debug)]
pub struct Distances {
    pub stop: f64,
    pub slow: f64,
    /// Speed commanded while an obstacle is inside the slow distance.
    pub creep: f64,
}

/// One avoidance decision.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Avoidance {
    pub velocity: f64,
    pub angular: f64,
    /// The derived activity `emergency`.
    pub emergency: f64,
    pub output: BehaviourOutput,
}

/// Obstacle avoidance on a scan for the activation ι: nothing to do beyond the slow
/// distance; closer, creep and turn away from the nearer side, active in proportion to
/// the closeness; inside the stop distance, stop and turn with full activity
/// (`emergency`).
pub fn avoid(scan: &LaserScan, d: &Distances, activation: f64) -> Avoidance {
    let front = nearest(scan, -0.6, 0.6);
    let left = nearest(scan, 0.2, 1.4);
    let right = nearest(scan, -1.4, -0.2);
    // A slow distance inside the stop distance would divide by ≤ 0.
    let slow = d.slow.max(d.stop + 1e-3);
    let away = if left >= right { 1.0 } else { -1.0 };
    if activation <= 0.0 || front >= slow {
        return Avoidance::default();
    }
    if front <= d.stop {
        return Avoidance {
            velocity: 0.0,
            angular: away * 0.4,
            emergency: activation,
            output: BehaviourOutput {
                activity: activation,
                target_rating: 1.0,
            },
        };
    }
    let closeness = ((slow - front) / (slow - d.stop)).clamp(0.0, 1.0);
    Avoidance {
        velocity: d.creep,
        angular: away * 0.5 * closeness,
        emergency: 0.0,
        output: BehaviourOutput {
            activity: activation * closeness,
            target_rating: closeness,
        },
    }
}

/// Fuses the (velocity, angular velocity) commands of its channels by their activities:
/// `ferroc_std`'s pair fusion with this library's port names.
pub struct VelocityFusion(PairFusion);

impl Behaviour for VelocityFusion {
    const NAME: &'static str = "warehouse.VelocityFusion";
    const DOC: &'static str = "iB2C fusion of (velocity, angular velocity) commands";
    const FUSION: bool = true;

    fn create(m: &mut Setup<'_>) -> Self {
        VelocityFusion(PairFusion::declare(
            m,
            [("velocity", "m/s"), ("angular_velocity", "rad/s")],
            ["fused_velocity", "fused_angular_velocity"],
        ))
    }

    fn transfer(&mut self, activation: f64, _derived: &mut [f64]) -> BehaviourOutput {
        self.0.step(activation)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn steer(heading_error: f64, remaining: f64) -> Steering {
        Steering {
            curvature: 0.0,
            heading_error,
            remaining,
        }
    }

    #[test]
    fn pursuit_slows_on_the_final_approach_and_turns_on_the_spot() {
        assert_eq!(pursue(steer(0.0, 5.0), 1.2), (1.2, 0.0));
        let (v, _) = pursue(steer(0.0, 0.5), 1.2);
        assert!((v - 0.4).abs() < 1e-12);
        // Never slower than a creep, so it arrives.
        assert_eq!(pursue(steer(0.0, 0.001), 1.2).0, CREEP);
        // Goal behind: stop and turn towards it.
        assert_eq!(pursue(steer(-2.0, 5.0), 1.2), (0.0, -MAX_TURN));
        // A speed limit of zero stands still.
        assert_eq!(pursue(steer(0.0, 5.0), 0.0).0, 0.0);
    }

    /// A 180° scan (1° apart) with one obstacle `at` metres away at `bearing` degrees.
    fn scan_with(bearing: i32, at: f32) -> LaserScan {
        let mut ranges = vec![10.0; 181];
        ranges[(bearing + 90) as usize] = at;
        LaserScan {
            angle_min: -PI / 2.0,
            angle_increment: PI / 180.0,
            ranges,
            ..LaserScan::default()
        }
    }

    const LIMITS: Distances = Distances {
        stop: 0.35,
        slow: 1.2,
        creep: 0.05,
    };

    #[test]
    fn avoidance_grows_with_closeness_and_stops_inside_the_stop_distance() {
        // Nothing close: inactive, standing still.
        assert_eq!(
            avoid(&scan_with(0, 5.0), &LIMITS, 1.0),
            Avoidance::default()
        );
        // Half way between slow and stop distance, slightly right: half active, creeping,
        // turning left (away).
        let r = avoid(&scan_with(-20, 0.775), &LIMITS, 1.0);
        assert!((r.output.activity - 0.5).abs() < 1e-6, "{r:?}");
        assert_eq!(r.velocity, 0.05);
        assert!(r.angular > 0.0 && r.emergency == 0.0);
        // Left of the heading: turns right.
        assert!(avoid(&scan_with(20, 0.775), &LIMITS, 1.0).angular < 0.0);
        // Inside the stop distance: emergency, stop, full activity (never above ι).
        let r = avoid(&scan_with(5, 0.2), &LIMITS, 0.8);
        assert_eq!(
            (r.velocity, r.emergency, r.output.activity),
            (0.0, 0.8, 0.8)
        );
        // Beside or behind the robot does not count as ahead.
        assert_eq!(
            avoid(&scan_with(90, 0.2), &LIMITS, 1.0).output.activity,
            0.0
        );
        // Not activated: nothing.
        assert_eq!(
            avoid(&scan_with(0, 0.2), &LIMITS, 0.0),
            Avoidance::default()
        );
    }

    #[test]
    fn the_nearest_range_per_sector() {
        let scan = LaserScan {
            angle_min: -PI / 2.0,
            angle_increment: PI / 2.0,
            ranges: vec![1.0, 2.0, f32::NAN],
            ..LaserScan::default()
        };
        // Beams at -90°, 0°, +90°.
        assert_eq!(nearest(&scan, -0.1, 0.1), 2.0);
        assert_eq!(nearest(&scan, -2.0, 0.1), 1.0);
        assert_eq!(nearest(&scan, 1.0, 2.0), f64::INFINITY);
        assert_eq!(nearest(&LaserScan::default(), -1.0, 1.0), f64::INFINITY);
    }
}
