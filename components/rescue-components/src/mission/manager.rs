//! `rescue.MissionManager`: keeps the victim list on the station, sends the robot to
//! unconfirmed victims and to frontiers, and home when nothing is left to explore.

use super::{approach_goal, nearest_frontier, CONFIRMED};
use crate::grid::Grid;
use crate::types::{Map, Pose2D, VictimList};
use ferroc_runtime::console;
use ferroc_runtime::module::{In, Module, ModuleType, Out, Parameter, Setup};

/// A goal within this distance of the robot counts as reached (m).
const REACHED: f64 = 0.5;
/// Obstacles are grown by this much for planning on the station (m).
const INFLATE: f64 = 0.35;

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
    current: Option<Pose2D>,
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
            current: None,
            done: false,
            report_failed: false,
        }
    }
}

impl MissionManager {
    /// The goal the robot should drive to now, if any.
    fn choose_goal(&mut self, pose: &Pose2D) -> Option<Pose2D> {
        if let Some(v) = self.list.victims.iter().find(|v| v.confidence < CONFIRMED) {
            return Some(approach_goal(pose, v));
        }
        let keep = self.current.filter(|g| g.distance_to(pose) > REACHED);
        if keep.is_some() || self.done {
            return keep;
        }
        let grid = self.grid.as_ref()?;
        let home = self.home.unwrap_or(*pose);
        let min_count = (self.frontier_min_size.get() / grid.step()).ceil().max(1.0) as usize;
        let found = nearest_frontier(grid, pose, &home, self.search_radius.get(), min_count);
        if found.is_none() {
            self.done = true;
            console::line(&format!(
                "[{}] nothing left to explore: returning home",
                self.mission_name.value()
            ));
            self.command.publish("return_home".to_string());
            return Some(home);
        }
        found
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
            self.grid = Some(Grid::from_map(&self.map.get(), INFLATE));
            // New map, new frontiers: the current goal may be explored already.
            self.current = self.current.filter(|_| self.done);
        }
        let Some(pose) = self.pose.try_pop() else {
            return; // no pose yet, or none new
        };
        // The mission starts where the robot was first seen.
        self.home.get_or_insert(pose);
        let goal = self.choose_goal(&pose);
        let new = match (goal, self.current) {
            (Some(g), Some(c)) => g.distance_to(&c) > 0.1,
            (Some(_), None) => true,
            (None, _) => false,
        };
        self.current = goal;
        if let (true, Some(goal)) = (new, goal) {
            self.goal.publish(goal);
        }
    }
}
