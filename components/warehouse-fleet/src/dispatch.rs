//! The fleet manager's dispatch, apart from ports: pending orders, what each robot
//! reported, and which robot gets which order.

use crate::{RobotStatus, Task};

/// Most orders kept waiting; more are refused (the WMS re-sends what it still needs).
pub const MAX_PENDING: usize = 256;
/// Auction: a robot's bid grows by this many metres per unit of missing charge ...
const BID_PER_MISSING_CHARGE: f64 = 10.0;
/// ... and per task it has done already (spreads the work).
const BID_PER_TASK_DONE: f64 = 0.5;

/// How an order finds its robot.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Strategy {
    /// The free robot closest to the pickup.
    #[default]
    Nearest,
    /// The free robots in turn.
    RoundRobin,
    /// The lowest bid: distance, plus penalties for low charge and for work done.
    Auction,
}

impl Strategy {
    /// The parameter's text (`nearest`, `round_robin`, `auction`).
    pub fn parse(text: &str) -> Option<Self> {
        match text {
            "nearest" => Some(Strategy::Nearest),
            "round_robin" => Some(Strategy::RoundRobin),
            "auction" => Some(Strategy::Auction),
            _ => None,
        }
    }
}

/// A task sent to a robot, until the robot reports it done.
#[derive(Clone, Debug)]
struct Assignment {
    task: Task,
    /// Dispatch cycle it was sent in.
    since: u64,
    /// The robot reported it as its task.
    acknowledged: bool,
}

#[derive(Clone, Debug, Default)]
struct Robot {
    status: Option<RobotStatus>,
    assignment: Option<Assignment>,
    /// It let an assignment time out: skipped until it reports again.
    silent: bool,
}

impl Robot {
    fn free(&self) -> bool {
        self.assignment.is_none() && !self.silent && self.status.is_some_and(|s| !s.busy)
    }
}

/// What one dispatch cycle decided.
#[derive(Clone, Debug, Default)]
pub struct Round {
    /// Tasks to send: (robot, task).
    pub sent: Vec<(usize, Task)>,
    /// Assignments taken back because no robot acknowledged them: (robot, task id).
    pub taken_back: Vec<(usize, u64)>,
}

/// Pending orders and the robots' state; one [`dispatch`](Self::dispatch) per cycle.
#[derive(Clone, Debug, Default)]
pub struct Dispatcher {
    robots: Vec<Robot>,
    pending: Vec<Task>,
    cycle: u64,
    next_robot: usize,
}

impl Dispatcher {
    /// A dispatcher for `robots` robots (indices 0 .. robots-1).
    pub fn new(robots: usize) -> Self {
        Dispatcher {
            robots: vec![Robot::default(); robots],
            ..Dispatcher::default()
        }
    }

    /// Queues an order; false if too many are waiting (it is refused).
    pub fn add_order(&mut self, task: Task) -> bool {
        if self.pending.len() >= MAX_PENDING {
            return false;
        }
        self.pending.push(task);
        true
    }

    /// Orders waiting for a robot.
    pub fn pending(&self) -> usize {
        self.pending.len()
    }

    /// A new status report of robot `k` (out-of-range indices are ignored).
    pub fn report(&mut self, k: usize, status: RobotStatus) {
        let Some(robot) = self.robots.get_mut(k) else {
            return;
        };
        robot.silent = false;
        if let Some(a) = &mut robot.assignment {
            if status.task_id == a.task.id {
                a.acknowledged = true;
                if !status.busy {
                    robot.assignment = None;
                }
            }
        }
        robot.status = Some(status);
    }

    /// Takes back assignments no robot acknowledged within `reassign_after` cycles.
    /// Returns (robot, task id) of each.
    fn take_back(&mut self, reassign_after: u64) -> Vec<(usize, u64)> {
        let mut taken = Vec::new();
        for (k, robot) in self.robots.iter_mut().enumerate() {
            let expired = robot.assignment.as_ref().is_some_and(|a| {
                !a.acknowledged && self.cycle.saturating_sub(a.since) >= reassign_after
            });
            if expired {
                if let Some(a) = robot.assignment.take() {
                    taken.push((k, a.task.id));
                    self.pending.push(a.task);
                }
                robot.silent = true;
            }
        }
        taken
    }

    /// The free robot an order goes to, if any.
    fn choose(&self, strategy: Strategy, task: &Task) -> Option<usize> {
        let free = self.robots.iter().enumerate().filter(|(_, r)| r.free());
        let cost = |r: &Robot| -> f64 {
            let s = r.status.unwrap_or_default();
            let distance = s.pose.distance_to(&task.pickup);
            match strategy {
                Strategy::Auction => {
                    let missing = (1.0 - f64::from(s.battery_charge)).clamp(0.0, 1.0);
                    distance
                        + BID_PER_MISSING_CHARGE * missing
                        + BID_PER_TASK_DONE * f64::from(s.tasks_done)
                }
                _ => distance,
            }
        };
        match strategy {
            Strategy::RoundRobin => {
                let n = self.robots.len();
                (0..n)
                    .map(|i| (self.next_robot + i) % n)
                    .find(|&k| self.robots[k].free())
            }
            // The first of equal costs wins; a robot whose cost is not a number loses.
            _ => free
                .map(|(k, r)| (k, cost(r)))
                .filter(|(_, c)| !c.is_nan())
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .map(|(k, _)| k),
        }
    }

    /// One dispatch cycle: takes back timed-out assignments, then gives the pending
    /// orders (highest priority, then earliest deadline, then oldest first) to free
    /// robots.
    pub fn dispatch(&mut self, strategy: Strategy, reassign_after: u64) -> Round {
        self.cycle += 1;
        let taken_back = self.take_back(reassign_after);
        self.pending.sort_by(|a, b| {
            b.priority
                .cmp(&a.priority)
                .then(a.deadline.cmp(&b.deadline))
                .then(a.id.cmp(&b.id))
        });
        let mut sent = Vec::new();
        let mut waiting = Vec::new();
        for task in std::mem::take(&mut self.pending) {
            match self.choose(strategy, &task) {
                Some(k) => {
                    self.robots[k].assignment = Some(Assignment {
                        task: task.clone(),
                        since: self.cycle,
                        acknowledged: false,
                    });
                    self.next_robot = (k + 1) % self.robots.len().max(1);
                    sent.push((k, task));
                }
                None => waiting.push(task),
            }
        }
        self.pending = waiting;
        Round { sent, taken_back }
    }
}

#[cfg(test)]
#[path = "dispatch_tests.rs"]
mod tests;
