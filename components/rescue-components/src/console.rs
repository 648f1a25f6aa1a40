//! `rescue.OperatorConsole`: what the operator watches, as text at a human rate.

use crate::types::{Map, Pose2D, VictimList, UNKNOWN};
use ferroc_runtime::console;
use ferroc_runtime::module::{In, Module, ModuleType, Out, Parameter, Setup};

/// Prints a status line once per second of console time (every `refresh` cycles: the
/// console's thread runs at its refresh rate) and each newly found victim at once;
/// starts the mission with the operator's `explore` command.
pub struct OperatorConsole {
    map: In<Map>,
    pose: In<Pose2D>,
    victims: In<VictimList>,
    robot_state: In<String>,
    battery_voltage: In<f64>,
    command: Out<String>,
    title: Parameter<String>,
    refresh: Parameter<f64>,
    cycles: u64,
    /// Area of the map known so far (m²), recomputed when a map arrives.
    explored: f64,
    /// Victims already announced.
    announced: usize,
}

impl ModuleType for OperatorConsole {
    const NAME: &'static str = "rescue.OperatorConsole";
    const DOC: &'static str = "Operator GUI: map, robot, victims and mission commands";

    fn create(m: &mut Setup<'_>) -> Self {
        OperatorConsole {
            map: m.input("map").build(),
            pose: m.input("pose").build(),
            victims: m.input("victims").build(),
            robot_state: m.input("robot_state").build(),
            battery_voltage: m.input("battery_voltage").unit("V").build(),
            command: m.output("command").build(),
            title: m
                .param("title")
                .default("rescue station".to_string())
                .build(),
            refresh: m
                .param("refresh")
                .unit("Hz")
                .range(1.0, 60.0)
                .default(20.0)
                .build(),
            cycles: 0,
            explored: 0.0,
            announced: 0,
        }
    }
}

/// Known area of a map (m²).
pub fn explored_area(map: &Map) -> f64 {
    let known = map.cells.iter().filter(|&&c| c != UNKNOWN).count();
    known as f64 * map.resolution * map.resolution
}

impl Module for OperatorConsole {
    fn update(&mut self) {
        if self.cycles == 0 {
            self.command.publish("explore".to_string());
        }
        self.cycles += 1;
        let refresh = self.refresh.get().max(1.0);
        let t = self.cycles as f64 / refresh;
        if self.map.changed() {
            self.explored = explored_area(&self.map.get());
        }
        let victims = self.victims.get();
        for v in victims.victims.iter().skip(self.announced) {
            console::line(&format!(
                "[{}] t={t:5.1} s victim #{} found at x={:+.2} m y={:+.2} m (confidence {:.2})",
                self.title.value(),
                v.id,
                v.x,
                v.y,
                v.confidence
            ));
        }
        self.announced = self.announced.max(victims.victims.len());
        if self.cycles % (refresh.round() as u64).max(1) != 0 {
            return;
        }
        // Inputs from the robot's part are stale before its first values and while it
        // is gone: show that, never its old or default values as if they were news.
        if self.pose.is_stale() && self.battery_voltage.is_stale() && self.robot_state.is_stale() {
            let since = match self.pose.age() {
                Some(age) => format!("for {:.1} s", age.as_secs_f64()),
                None => "yet".to_string(),
            };
            console::line(&format!(
                "[{}] t={t:5.1} s no data from the robot {since} (victims {})",
                self.title.value(),
                victims.victims.len()
            ));
            return;
        }
        let p = self.pose.get();
        let state = self.robot_state.get();
        let confirmed = victims
            .victims
            .iter()
            .filter(|v| v.confidence >= crate::mission::CONFIRMED)
            .count();
        console::line(&format!(
            "[{}] t={t:5.1} s {:<15} x={:+.2} m y={:+.2} m heading={:>4.0}° battery {:.2} V explored {:>5.1} m² victims {} ({confirmed} confirmed)",
            self.title.value(),
            if state.is_empty() { "-" } else { state.as_str() },
            p.x,
            p.y,
            p.theta.to_degrees(),
            self.battery_voltage.get(),
            self.explored,
            victims.victims.len()
        ));
    }
}
