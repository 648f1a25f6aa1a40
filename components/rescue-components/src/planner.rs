//! `rescue.PathPlanner`: plans on the occupancy grid to the current goal, follows the
//! path, and keeps clear of obstacles in the laser scan.

use crate::grid::{Grid, FAR};
use crate::types::{wrap_angle, LaserScan, Map, Pose2D, Velocity2D};
use ferroc_runtime::module::{In, Module, ModuleType, Out, Parameter, Setup};
use ferroc_runtime::resource::LockSlot;
use std::time::Duration;

/// The path is followed towards a point this many cells ahead on it.
const LOOK_AHEAD: usize = 4;
/// The corridor the robot drives through is this much wider than its body, each side.
const SIDE_MARGIN: f64 = 0.1;
/// Extra clearance kept beyond the robot radius (m).
const MARGIN: f64 = 0.15;
/// Once blocked, the robot turns until this much more than the stopping distance is
/// free ahead, in a corridor [`WIDEN`] wider each side, so that it does not turn back
/// and forth at the edge of an obstacle.
const CLEAR: f64 = 0.3;
const WIDEN: f64 = 0.15;
/// Paths keep this far from obstacles beyond the robot radius: more than the stopping
/// distance, so following a path round a corner does not stop the robot.
const PATH_CLEARANCE: f64 = MARGIN + 0.15;

/// What the robot may do.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits {
    /// m/s.
    pub max_speed: f64,
    /// rad/s.
    pub max_turn: f64,
    /// Radius of the robot (m).
    pub radius: f64,
}

/// The velocity that drives from `pose` towards `target` (map frame) without hitting
/// what `scan` sees: turn towards the target, slow down for obstacles ahead and for
/// large heading errors, and when blocked turn on the spot to the more open side
/// until the way ahead is clear (`escape` remembers that side between cycles).
pub fn steer(
    pose: &Pose2D,
    target: (f64, f64),
    scan: &LaserScan,
    limits: Limits,
    escape: &mut Option<f64>,
) -> Velocity2D {
    let Limits {
        max_speed,
        max_turn,
        radius,
    } = limits;
    let error = wrap_angle((target.1 - pose.y).atan2(target.0 - pose.x) - pose.theta);
    // Free distance ahead in the corridor the body sweeps, and in a wider one.
    let (mut front, mut wide, mut left, mut right) = (f64::INFINITY, f64::INFINITY, 0.0, 0.0);
    for (i, &r) in scan.ranges.iter().enumerate() {
        let (b, r) = (scan.bearing(i), f64::from(r));
        if !r.is_finite() {
            continue;
        }
        // An obstacle in the corridor the body sweeps when driving straight on.
        let (ahead, aside) = (r * b.cos(), r * b.sin());
        if ahead > 0.0 && aside.abs() <= radius + SIDE_MARGIN {
            front = front.min(ahead);
        }
        if ahead > 0.0 && aside.abs() <= radius + SIDE_MARGIN + WIDEN {
            wide = wide.min(ahead);
        }
        if b > 0.0 {
            left += r;
        } else {
            right += r;
        }
    }
    let stop = radius + MARGIN;
    let turning = match *escape {
        Some(side) if wide < stop + CLEAR => Some(side),
        _ if front < stop => Some(if left >= right { 1.0 } else { -1.0 }),
        _ => None,
    };
    *escape = turning;
    if let Some(side) = turning {
        return Velocity2D {
            linear: 0.0,
            angular: side * max_turn,
        };
    }
    let room = ((front - stop) / 1.0).clamp(0.0, 1.0);
    Velocity2D {
        linear: max_speed * room * error.cos().max(0.0).powi(2),
        angular: (1.5 * error).clamp(-max_turn, max_turn),
    }
}

/// Where to drive next: a point [`LOOK_AHEAD`] cells along the cheapest path from the
/// robot's cell to the goal, given `costs` from the goal. `None` if the robot's cell
/// is not connected to the goal.
pub fn carrot(grid: &Grid, costs: &[u32], pose: &Pose2D) -> Option<(f64, f64)> {
    let mut at = grid.cell_of(pose.x, pose.y)?;
    if costs.get(at).is_none_or(|&c| c == FAR) {
        // Grazing an obstacle: leave through the cheapest neighbour.
        at = grid.downhill(costs, at)?;
    }
    for _ in 0..LOOK_AHEAD {
        match grid.downhill(costs, at) {
            Some(next) => at = next,
            None => break,
        }
    }
    Some(grid.centre(at))
}

/// Follows the goal from the station on the latest map; wanders towards open space
/// while it has no goal.
pub struct PathPlanner {
    pose: In<Pose2D>,
    map: In<Map>,
    goal: In<Pose2D>,
    scan: In<LaserScan>,
    cmd: Out<Velocity2D>,
    path_length: Out<f64>,
    goal_reached: Out<bool>,
    max_speed: Parameter<f64>,
    max_turn_rate: Parameter<f64>,
    goal_tolerance: Parameter<f64>,
    robot_radius: Parameter<f64>,
    replan_period: Parameter<Duration>,
    grid_lock: LockSlot,
    target: Option<Pose2D>,
    reached: bool,
    grid: Option<Grid>,
    /// Path costs from the target over `grid`.
    costs: Vec<u32>,
    /// Scan time of the last plan, and whether the map changed since.
    planned: Option<Duration>,
    map_changed: bool,
    /// The side the robot turns to while blocked.
    escape: Option<f64>,
}

impl ModuleType for PathPlanner {
    const NAME: &'static str = "rescue.PathPlanner";
    const DOC: &'static str =
        "Plans on the occupancy grid and follows the path to the current goal";

    fn create(m: &mut Setup<'_>) -> Self {
        PathPlanner {
            pose: m.input("pose").required().build(),
            map: m.input("map").build(),
            goal: m
                .input("goal")
                .doc("new goals arrive through a queue from the station")
                .build(),
            scan: m
                .input("scan")
                .doc("for reactive obstacle avoidance")
                .build(),
            cmd: m.output("cmd").build(),
            path_length: m.output("path_length").unit("m").build(),
            goal_reached: m.output("goal_reached").build(),
            max_speed: m
                .param("max_speed")
                .unit("m/s")
                .range(0.0, 1.5)
                .doc("driven at run time by the mission context")
                .build(),
            max_turn_rate: m
                .param("max_turn_rate")
                .unit("rad/s")
                .range(0.0, 3.0)
                .default(1.0)
                .build(),
            goal_tolerance: m
                .param("goal_tolerance")
                .unit("m")
                .range(0.01, 2.0)
                .default(0.2)
                .build(),
            robot_radius: m
                .param("robot_radius")
                .unit("m")
                .range(0.05, 2.0)
                .default(0.3)
                .build(),
            replan_period: m
                .param("replan_period")
                .range(0.05, 10.0)
                .default(Duration::from_millis(500))
                .build(),
            grid_lock: m.lock("grid"),
            target: None,
            reached: false,
            grid: None,
            costs: Vec::new(),
            planned: None,
            map_changed: false,
            escape: None,
        }
    }
}

impl PathPlanner {
    /// Rebuilds the planning grid from the shared map (under its lock) and the path
    /// costs from the target.
    fn replan(&mut self) {
        if std::mem::take(&mut self.map_changed) {
            let _grid = self.grid_lock.lock();
            let map = self.map.get();
            self.grid = Some(Grid::from_map(
                &map,
                self.robot_radius.get(),
                PATH_CLEARANCE,
            ));
        }
        self.costs.clear();
        if let (Some(grid), Some(goal)) = (&self.grid, &self.target) {
            if let Some(cell) = grid.cell_of(goal.x, goal.y) {
                self.costs = grid.costs_from(cell);
            }
        }
    }
}

impl Module for PathPlanner {
    fn update(&mut self) {
        let pose = self.pose.get();
        let mut replan = false;
        // Several goals may be queued: the newest counts.
        while let Some(goal) = self.goal.try_pop() {
            if goal.x.is_finite() && goal.y.is_finite() {
                self.target = Some(goal);
                self.reached = false;
                replan = true;
            }
        }
        if self.map.changed() {
            self.map_changed = true;
        }
        let scan = self.scan.get();
        let due = self
            .planned
            .is_none_or(|last| scan.stamp >= last + self.replan_period.get());
        if replan || (due && self.map_changed) {
            self.planned = Some(scan.stamp);
            self.replan();
        }
        let limits = Limits {
            max_speed: self.max_speed.get(),
            max_turn: self.max_turn_rate.get(),
            radius: self.robot_radius.get(),
        };
        let max_turn = limits.max_turn;
        let tolerance = self.goal_tolerance.get();
        let command = match self.target {
            Some(goal) if self.reached || pose.distance_to(&goal) <= tolerance => {
                // There: turn to the goal's heading (where the station wants the
                // camera to look), then stand.
                self.reached = true;
                self.path_length.publish(0.0);
                let turn = wrap_angle(goal.theta - pose.theta);
                Velocity2D {
                    linear: 0.0,
                    angular: if turn.abs() > 0.05 {
                        (1.5 * turn).clamp(-max_turn, max_turn)
                    } else {
                        0.0
                    },
                }
            }
            Some(goal) => {
                let on_path = self.grid.as_ref().and_then(|grid| {
                    let cell = grid.cell_of(pose.x, pose.y)?;
                    let cost = *self.costs.get(cell)?;
                    (cost != FAR).then(|| {
                        self.path_length
                            .publish(f64::from(cost) / 10.0 * grid.step());
                        carrot(grid, &self.costs, &pose)
                    })?
                });
                let target = on_path.unwrap_or_else(|| {
                    self.path_length.publish(pose.distance_to(&goal));
                    (goal.x, goal.y)
                });
                steer(&pose, target, &scan, limits, &mut self.escape)
            }
            None => {
                // No goal yet: drive towards the most open direction ahead.
                let open = (0..scan.ranges.len())
                    .max_by(|&a, &b| scan.ranges[a].total_cmp(&scan.ranges[b]))
                    .map_or(0.0, |i| scan.bearing(i));
                let heading = pose.theta + open;
                let target = (pose.x + heading.cos(), pose.y + heading.sin());
                steer(&pose, target, &scan, limits, &mut self.escape)
            }
        };
        self.goal_reached.publish(self.reached);
        self.cmd.publish(command);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drivers::sweep;
    use crate::hardware::{Robot, PHYSICS_STEP};

    #[test]
    fn steering_turns_towards_the_target_and_stops_before_walls() {
        let robot = Robot::default();
        let scan = sweep(&robot, &robot.pose, 30.0, Duration::ZERO);
        // Target straight ahead, 6 m of room: full speed, no turn.
        let limits = Limits {
            max_speed: 0.5,
            max_turn: 1.0,
            radius: 0.3,
        };
        let mut escape = None;
        let v = steer(&robot.pose, (0.0, 0.0), &scan, limits, &mut escape);
        assert!(
            (v.linear - 0.5).abs() < 1e-9 && v.angular.abs() < 1e-9,
            "{v:?}"
        );
        // Target to the left: turn left (positive), slower.
        let v = steer(&robot.pose, (-4.0, 3.0), &scan, limits, &mut escape);
        assert!(v.angular > 0.0 && v.linear < 0.1, "{v:?}");
        // Facing the west wall 0.4 m away: stop and turn on the spot.
        let mut near = Robot::default();
        near.pose = Pose2D {
            x: -5.6,
            y: 0.0,
            theta: std::f64::consts::PI,
        };
        let scan = sweep(&near, &near.pose, 30.0, Duration::ZERO);
        let v = steer(&near.pose, (-10.0, 0.0), &scan, limits, &mut escape);
        assert_eq!(v.linear, 0.0);
        assert_eq!(v.angular.abs(), 1.0);
        assert_eq!(escape, Some(v.angular));
        // Turned a little, 0.5 m free ahead (past the stopping distance of 0.45 m but
        // not clear by 0.3 m more): keeps turning the same way.
        near.pose = Pose2D {
            x: -5.5,
            y: 0.0,
            theta: std::f64::consts::PI - 0.1,
        };
        let scan = sweep(&near, &near.pose, 30.0, Duration::ZERO);
        let again = steer(&near.pose, (-10.0, 0.0), &scan, limits, &mut escape);
        assert_eq!(again, v);
        // Facing open space: the escape ends and it drives.
        near.pose.theta = 0.0;
        let scan = sweep(&near, &near.pose, 30.0, Duration::ZERO);
        let free = steer(&near.pose, (-4.0, 0.0), &scan, limits, &mut escape);
        assert!(free.linear > 0.0 && escape.is_none(), "{free:?}");
    }

    #[test]
    fn following_the_plan_drives_round_the_partition_to_the_goal() {
        use crate::mapper::{empty_map, integrate};
        let mut robot = Robot::default();
        let mut map = empty_map(0.05, 40.0).unwrap();
        let goal = (4.0, 2.0); // in the middle room, beyond the partition's north end
        let mut costs = Vec::new();
        let mut grid = None;
        let mut escape = None;
        for step in 0..2400 {
            let scan = sweep(&robot, &robot.pose, 30.0, robot.time);
            if step % 20 == 0 {
                integrate(&mut map, &scan, &robot.pose);
                let g = Grid::from_map(&map, 0.32, PATH_CLEARANCE);
                costs = g.costs_from(g.cell_of(goal.0, goal.1).unwrap());
                grid = Some(g);
            }
            let target = grid
                .as_ref()
                .and_then(|g| carrot(g, &costs, &robot.pose))
                .unwrap_or(goal);
            let limits = Limits {
                max_speed: 0.5,
                max_turn: 1.0,
                radius: 0.32,
            };
            let v = steer(&robot.pose, target, &scan, limits, &mut escape);
            robot.step(v.linear, v.angular, PHYSICS_STEP);
            if (robot.pose.x - goal.0).hypot(robot.pose.y - goal.1) < 0.25 {
                assert!(robot.time < Duration::from_secs(60), "{:?}", robot.time);
                assert!(!robot.bumper);
                return;
            }
        }
        panic!("not at the goal after a minute: {:?}", robot.pose);
    }
}
