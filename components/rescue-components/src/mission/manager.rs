//! `rescue.MissionManager`: keeps the victim list on the station, sends the robot to
//! unconfirmed victims and to frontiers, and home when nothing is left to explore.

use super::{approach_goal, nearest_unsearched, Searched, CONFIRMED};
use crate::grid::Grid;
use crate::types::{Map, Pose2D, VictimList};
use ferroc_runtime::console;
use ferroc_runtime::module::{In, Module, ModuleType, Out, Parameter, Setup};

/// A goal within this distance of the robot counts as reached (m).
const REACHED: f64 = 0.5;
/// A goal is given up when the robot has stayed within [`STALL_RADIUS`] of one place
/// for this many pose updates without reaching it (the goal was placed on a map that
/// did not show the obstacle next to it yet, say, or a victim is out of view from
/// its approach goal). Progress is movement, not distance to the goal: a path round
/// a wall leads away from the goal first.
const STALL_UPDATES: u32 = 200;
const STALL_RADIUS: f64 = 0.25;
/// The robot's radius, and the clearance its goals keep from obstacles (m).
const RADIUS: f64 = 0.3;
const CLEARANCE: f64 = 0.15;

/// Mission supervision on the base station.
pub struct MissionManager {
    victims: In<VictimList>,
    map: In<Map>,
    pose: In<Pose2D>,
    operator_command: In<String>,
    goal: Out<Pose2D>,
    command: Out<String>,
    victims_found: Out<u32>,
    mission_name: Parameter<String>,
    search_radius: Parameter<f64>,
    frontier_min_size: Parameter<f64>,
    report_file: Parameter<String>,
    home: Option<Pose2D>,
    list: VictimList,
    grid: Option<Grid>,
    searched: Searched,
    current: Option<Pose2D>,
    /// The victim the current goal approaches.
    approaching: Option<u32>,
    /// Victims whose approach was given up.
    given_up: Vec<u32>,
    progress: Progress,
    /// The mission has nothing left to explore.
    done: bool,
    report_failed: bool,
}

impl ModuleType for MissionManager {
    const NAME: &'static str = "rescue.MissionManager";
    const DOC: &'static str = "Mission supervision on the base station";

    fn create(m: &mut Setup<'_>) -> Self {
        MissionManager {
            victims: m.input("victims").build(),
            map: m.input("map").build(),
            pose: m.input("pose").build(),
            operator_command: m.input("operator_command").build(),
            goal: m.output("goal").build(),
            command: m.output("command").build(),
            victims_found: m.output("victims_found").build(),
            mission_name: m.param("mission_name").build(),
            search_radius: m
                .param("search_radius")
                .unit("m")
                .range(1.0, 500.0)
                .default(30.0)
                .build(),
            frontier_min_size: m
                .param("frontier_min_size")
                .unit("m")
                .range(0.1, 10.0)
                .default(1.0)
                .build(),
            report_file: m
                .param("report_file")
                .default("victims.json".to_string())
                .build(),
            home: None,
            list: VictimList::default(),
            grid: None,
            searched: Searched::default(),
            current: None,
            approaching: None,
            given_up: Vec::new(),
            progress: Progress::default(),
            done: false,
            report_failed: false,
        }
    }
}

impl MissionManager {
    /// The goal the robot should drive to now, if any.
    fn choose_goal(&mut self, pose: &Pose2D) -> Option<Pose2D> {
        let unconfirmed = self
            .list
            .victims
            .iter()
            .find(|v| v.confidence < CONFIRMED && !self.given_up.contains(&v.id));
        self.approaching = unconfirmed.map(|v| v.id);
        if let Some(v) = unconfirmed {
            return Some(approach_goal(pose, v));
        }
        let grid = self.grid.as_ref()?;
        // Keep driving to the current goal until it is reached or its floor searched.
        let keep = self.current.filter(|g| {
            let searched = grid
                .cell_of(g.x, g.y)
                .is_some_and(|i| self.searched.contains(i));
            g.distance_to(pose) > REACHED && (self.done || !searched)
        });
        if keep.is_some() || self.done {
            return keep;
        }
        let home = self.home.unwrap_or(*pose);
        let min_count = (self.frontier_min_size.get() / grid.step()).ceil().max(1.0) as usize;
        let radius = self.search_radius.get();
        let found = nearest_unsearched(grid, &self.searched, pose, &home, radius, min_count);
        if found.is_none() {
            self.done = true;
            console::line(&format!(
                "[{}] every reachable floor searched: returning home",
                self.mission_name.value()
            ));
            self.command.publish("return_home".to_string());
            return Some(home);
        }
        found
    }

    /// Stops pursuing `goal`: its victim stays unconfirmed, its floor counts as searched.
    fn give_up(&mut self, goal: &Pose2D) {
        console::line(&format!(
            "[{}] goal x={:+.2} m y={:+.2} m not reached: given up",
            self.mission_name.value(),
            goal.x,
            goal.y
        ));
        match self.approaching.take() {
            Some(id) => self.given_up.push(id),
            None => {
                if let Some(i) = self.grid.as_ref().and_then(|g| g.cell_of(goal.x, goal.y)) {
                    self.searched.mark(i);
                }
            }
        }
        self.current = None;
    }

    /// Writes the victim list as JSON; reports the first failure only.
    fn write_report(&mut self) {
        let text = match serde_json::to_string_pretty(&self.list) {
            Ok(text) => text,
            Err(e) => return console::line(&format!("warning: victim report: {e}")),
        };
        if let Err(e) = std::fs::write(self.report_file.value(), text) {
            if !std::mem::replace(&mut self.report_failed, true) {
                console::line(&format!(
                    "warning: [{}] cannot write the victim report {}: {e}",
                    self.mission_name.value(),
                    self.report_file.value()
                ));
            }
        }
    }
}

impl Module for MissionManager {
    fn update(&mut self) {
        while let Some(command) = self.operator_command.try_pop() {
            self.command.publish(String::clone(&command));
        }
        let mut newest = None;
        while let Some(list) = self.victims.try_pop() {
            newest = Some(list);
        }
        if let Some(list) = newest {
            if list.victims.len() != self.list.victims.len() {
                self.victims_found.publish(list.victims.len() as u32);
            }
            self.list.clone_from(&list);
            self.write_report();
        }
        if self.map.changed() {
            self.grid = Some(Grid::from_map(&self.map.get(), RADIUS, CLEARANCE));
        }
        let Some(pose) = self.pose.try_pop() else {
            return; // no pose yet, or none new
        };
        // The mission starts where the robot was first seen.
        self.home.get_or_insert(pose);
        if let Some(grid) = &self.grid {
            self.searched.look(grid, &pose);
        }
        let goal = self.choose_goal(&pose);
        let new = match (goal, self.current) {
            (Some(g), Some(c)) => g.distance_to(&c) > 0.1,
            (Some(_), None) => true,
            (None, _) => false,
        };
        self.current = goal;
        let Some(goal) = goal else { return };
        if new {
            self.progress = Progress::default();
            self.goal.publish(goal);
        } else if self.progress.stalled(&pose) {
            self.give_up(&goal);
        }
    }
}

/// Whether the robot is getting anywhere.
#[derive(Default)]
struct Progress {
    /// Where the robot was when it last moved on, and pose updates since.
    anchor: Option<Pose2D>,
    updates: u32,
}

impl Progress {
    /// Records a pose; true once the robot has stayed near one place for
    /// [`STALL_UPDATES`] updates.
    fn stalled(&mut self, pose: &Pose2D) -> bool {
        match self.anchor {
            Some(a) if a.distance_to(pose) <= STALL_RADIUS => self.updates += 1,
            _ => (self.anchor, self.updates) = (Some(*pose), 0),
        }
        self.updates > STALL_UPDATES
    }
}
