//! `warehouse.TaskExecutor`: one AGV's transport task — drive to the pickup, lift the
//! shelf, drive to the drop-off, set it down, report — plus parking and charging.

use crate::{Pose2D, RobotStatus, Task};
use ferroc_runtime::console;
use ferroc_runtime::module::{In, Module, ModuleType, Out, Parameter, Setup};

/// Within this distance of a goal that path following reports reached, the robot is
/// there (path following may still report the previous goal for a cycle).
const ARRIVAL: f64 = 0.05;
/// Charging ends this far above the threshold that started it.
const CHARGE_HYSTERESIS: f64 = 0.2;
/// Urgency of driving home (parking or to charge) and base urgency of a task.
const URGENCY_HOME: f64 = 0.4;
const URGENCY_TASK: f64 = 0.5;

/// What the robot is doing.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Phase {
    /// Driving to its home spot without a task.
    #[default]
    Parking,
    /// At home, waiting for a task.
    Idle,
    ToPickup,
    Lifting,
    ToDropoff,
    Lowering,
    /// Driving home and waiting there until the battery is charged.
    Charging,
}

/// What the executor reads in one cycle.
#[derive(Clone, Copy, Debug, Default)]
pub struct Inputs {
    pub pose: Pose2D,
    pub goal_reached: bool,
    pub loaded: bool,
    /// `None` until the battery monitor reported.
    pub charge: Option<f32>,
    pub protective_stop: bool,
}

/// What the executor commands in one cycle.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Commands {
    pub goal: Pose2D,
    pub urgency: f64,
    pub lift_raise: bool,
}

/// The task state machine, apart from ports so that it can be tested step by step.
#[derive(Clone, Debug, Default)]
pub struct Mission {
    pub phase: Phase,
    pub home: Pose2D,
    pub min_charge: f64,
    pub task: Option<Task>,
    pub last_task: u64,
    pub tasks_done: u32,
    raise: bool,
}

impl Mission {
    /// A mission for a robot parked at `home`.
    pub fn new(home: Pose2D, min_charge: f64) -> Self {
        Mission {
            home,
            min_charge,
            ..Mission::default()
        }
    }

    /// Whether it takes a new task now.
    pub fn ready(&self) -> bool {
        matches!(self.phase, Phase::Parking | Phase::Idle)
    }

    /// Starts `task` (call only when [`ready`](Self::ready)).
    pub fn start(&mut self, task: Task) {
        self.last_task = task.id;
        self.task = Some(task);
        self.phase = Phase::ToPickup;
    }

    fn goal(&self) -> Pose2D {
        match (self.phase, &self.task) {
            (Phase::ToPickup | Phase::Lifting, Some(t)) => t.pickup,
            (Phase::ToDropoff | Phase::Lowering, Some(t)) => t.dropoff,
            _ => self.home,
        }
    }

    /// One cycle: advances the phase on what the robot reports and says what to do.
    /// Returns the task finished in this cycle, if one was.
    pub fn step(&mut self, i: &Inputs) -> (Commands, Option<u64>) {
        let arrived = |goal: Pose2D| i.goal_reached && i.pose.distance_to(&goal) < ARRIVAL;
        let low = i.charge.is_some_and(|c| f64::from(c) < self.min_charge);
        let charged = i
            .charge
            .is_none_or(|c| f64::from(c) >= (self.min_charge + CHARGE_HYSTERESIS).min(0.95));
        let mut finished = None;
        match self.phase {
            Phase::Parking | Phase::Idle if low => self.phase = Phase::Charging,
            Phase::Parking if arrived(self.home) => self.phase = Phase::Idle,
            Phase::Charging if arrived(self.home) && charged => self.phase = Phase::Idle,
            Phase::ToPickup if arrived(self.goal()) => self.phase = Phase::Lifting,
            // The lift does not move while someone is in the protective field.
            Phase::Lifting if !i.protective_stop => {
                self.raise = true;
                if i.loaded {
                    self.phase = Phase::ToDropoff;
                }
            }
            Phase::ToDropoff if arrived(self.goal()) => self.phase = Phase::Lowering,
            Phase::Lowering if !i.protective_stop => {
                self.raise = false;
                if !i.loaded {
                    self.tasks_done = self.tasks_done.saturating_add(1);
                    finished = self.task.take().map(|t| t.id);
                    self.phase = Phase::Parking;
                }
            }
            _ => {}
        }
        let urgency = match (self.phase, &self.task) {
            (Phase::ToPickup | Phase::ToDropoff, Some(t)) => {
                URGENCY_TASK + (1.0 - URGENCY_TASK) * f64::from(t.priority) / 255.0
            }
            (Phase::Parking, _) => URGENCY_HOME,
            (Phase::Charging, _) if !arrived(self.home) => URGENCY_HOME,
            _ => 0.0,
        };
        let commands = Commands {
            goal: self.goal(),
            urgency,
            lift_raise: self.raise,
        };
        (commands, finished)
    }

    /// Working on a task or on the way to charge: not available for dispatch.
    pub fn busy(&self) -> bool {
        !self.ready()
    }
}

/// Whether a task can be driven: a non-zero id and finite coordinates.
fn valid(task: &Task) -> bool {
    let finite = |p: &Pose2D| p.x.is_finite() && p.y.is_finite() && p.theta.is_finite();
    task.id != 0 && finite(&task.pickup) && finite(&task.dropoff)
}

/// Executes the transport tasks of one AGV, one at a time, in arrival order.
pub struct TaskExecutor {
    task: In<Task>,
    pose: In<Pose2D>,
    goal_reached: In<bool>,
    loaded: In<bool>,
    battery_charge: In<f32>,
    protective_stop: In<bool>,
    goal: Out<Pose2D>,
    urgency: Out<f64>,
    lift_raise: Out<bool>,
    status: Out<RobotStatus>,
    robot_id: Parameter<u32>,
    mission: Mission,
    charge: Option<f32>,
}

impl ModuleType for TaskExecutor {
    const NAME: &'static str = "warehouse.TaskExecutor";
    const DOC: &'static str = "Executes transport tasks on one AGV";

    fn create(m: &mut Setup<'_>) -> Self {
        let mut metres = |name: &str| -> Parameter<f64> {
            m.param(name)
                .unit("m")
                .range(-1000.0, 1000.0)
                .default(0.0)
                .build()
        };
        let (mut home_x, mut home_y) = (metres("home_x"), metres("home_y"));
        let mut min_charge: Parameter<f64> = m
            .param("min_charge")
            .range(0.0, 1.0)
            .default(0.25)
            .doc("go charging below this state of charge")
            .build();
        let home = Pose2D {
            x: home_x.get(),
            y: home_y.get(),
            theta: 0.0,
        };
        TaskExecutor {
            task: m
                .input("task")
                .doc("new tasks; connect through a queue")
                .build(),
            pose: m.input("pose").required().build(),
            goal_reached: m.input("goal_reached").build(),
            loaded: m.input("loaded").build(),
            battery_charge: m.input("battery_charge").build(),
            protective_stop: m.input("protective_stop").build(),
            goal: m.output("goal").build(),
            urgency: m
                .output("urgency")
                .doc("0 .. 1; stimulates path following")
                .build(),
            lift_raise: m.output("lift_raise").build(),
            status: m.output("status").build(),
            robot_id: m.param("robot_id").range(1.0, 999.0).build(),
            mission: Mission::new(home, min_charge.get()),
            charge: None,
        }
    }
}

impl Module for TaskExecutor {
    fn update(&mut self) {
        if self.battery_charge.changed() {
            self.charge = Some(self.battery_charge.get()).filter(|c| c.is_finite());
        }
        let robot = self.robot_id.get();
        if self.mission.ready() {
            // Tasks wait in the input queue until the robot is free.
            while let Some(task) = self.task.try_pop() {
                if valid(&task) {
                    console::line(&format!(
                        "[agv {robot}] task {}: shelf at ({:.1}, {:.1}) to ({:.1}, {:.1})",
                        task.id, task.pickup.x, task.pickup.y, task.dropoff.x, task.dropoff.y
                    ));
                    self.mission.start(Task::clone(&task));
                    break;
                }
                console::line(&format!(
                    "[agv {robot}] task {} refused: no id or a position that is not a number",
                    task.id
                ));
            }
        }
        let inputs = Inputs {
            pose: self.pose.get(),
            goal_reached: *self.goal_reached.get(),
            loaded: *self.loaded.get(),
            charge: self.charge,
            protective_stop: *self.protective_stop.get(),
        };
        let (commands, finished) = self.mission.step(&inputs);
        if let Some(id) = finished {
            console::line(&format!(
                "[agv {robot}] task {id} delivered ({} done)",
                self.mission.tasks_done
            ));
        }
        self.goal.publish(commands.goal);
        self.urgency.publish(commands.urgency);
        self.lift_raise.publish(commands.lift_raise);
        self.status.publish(RobotStatus {
            robot_id: robot,
            pose: inputs.pose,
            // No battery reading yet: reported full, as it does not keep the robot from work.
            battery_charge: self.charge.unwrap_or(1.0),
            busy: self.mission.busy(),
            task_id: self.mission.last_task,
            tasks_done: self.mission.tasks_done,
            reserved: [0; 3],
        });
    }
}

#[cfg(test)]
#[path = "executor_tests.rs"]
mod tests;
