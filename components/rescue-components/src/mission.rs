//! `rescue.MissionContext` (on the robot) and `rescue.MissionManager` (on the station).

use crate::types::{Pose2D, Victim, VictimList};
use ferroc_runtime::module::{In, Module, ModuleType, Out, Parameter, Setup};

/// A victim seen at least this confidently is confirmed; below it the robot goes closer.
pub const CONFIRMED: f32 = 0.9;
/// The approach goal lies this far before an unconfirmed victim (m).
const APPROACH_DISTANCE: f64 = 2.0;

/// The robot's operating context (OpenRDK's "context switching").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Context {
    /// Standing still.
    Idle,
    /// Driving to frontiers at cruise speed, scanning fast.
    Explore,
    /// Going closer to a victim not yet confirmed: careful, more sensitive detector.
    ApproachVictim,
    /// Driving home.
    ReturnHome,
    /// The battery is low: careful and saving power.
    LowBattery,
}

impl Context {
    /// The name published on `state` and accepted as `initial_context`.
    pub fn as_str(self) -> &'static str {
        match self {
            Context::Idle => "idle",
            Context::Explore => "explore",
            Context::ApproachVictim => "approach_victim",
            Context::ReturnHome => "return_home",
            Context::LowBattery => "low_battery",
        }
    }

    /// The context an operator command asks for (`None`: not a command).
    pub fn of_command(command: &str) -> Option<Context> {
        match command.trim() {
            "explore" => Some(Context::Explore),
            "pause" | "idle" => Some(Context::Idle),
            "return_home" => Some(Context::ReturnHome),
            _ => None,
        }
    }

    /// The next context: a low battery overrides everything and stays; exploring
    /// switches to approaching while a victim is unconfirmed, and back.
    pub fn next(self, victims: &[Victim], battery: f64, low_battery: f64) -> Context {
        if self == Context::LowBattery || (battery > 0.0 && battery < low_battery) {
            return Context::LowBattery;
        }
        let unconfirmed = victims.iter().any(|v| v.confidence < CONFIRMED);
        match self {
            Context::Explore if unconfirmed => Context::ApproachVictim,
            Context::ApproachVictim if !unconfirmed => Context::Explore,
            other => other,
        }
    }
}

/// Chooses the context and drives other modules' parameters from it.
pub struct MissionContext {
    command: In<String>,
    victims: In<VictimList>,
    battery_voltage: In<f64>,
    max_speed: Out<f64>,
    laser_rate: Out<f64>,
    detection_threshold: Out<f64>,
    state: Out<String>,
    initial_context: Parameter<String>,
    cruise_speed: Parameter<f64>,
    careful_speed: Parameter<f64>,
    fast_scan_rate: Parameter<f64>,
    slow_scan_rate: Parameter<f64>,
    low_battery: Parameter<f64>,
    context: Option<Context>,
}

impl ModuleType for MissionContext {
    const NAME: &'static str = "rescue.MissionContext";
    const DOC: &'static str =
        "Switches the robot's operating context by driving other modules' parameters";

    fn create(m: &mut Setup<'_>) -> Self {
        MissionContext {
            command: m
                .input("command")
                .doc("operator commands: explore, pause, return_home")
                .build(),
            victims: m.input("victims").build(),
            battery_voltage: m.input("battery_voltage").unit("V").build(),
            max_speed: m.output("max_speed").unit("m/s").build(),
            laser_rate: m.output("laser_rate").unit("Hz").build(),
            detection_threshold: m.output("detection_threshold").build(),
            state: m.output("state").build(),
            initial_context: m
                .param("initial_context")
                .choices(&["explore", "idle", "return_home"])
                .default("idle".to_string())
                .build(),
            cruise_speed: speed(m, "cruise_speed", 0.6),
            careful_speed: speed(m, "careful_speed", 0.2),
            fast_scan_rate: rate(m, "fast_scan_rate", 20.0),
            slow_scan_rate: rate(m, "slow_scan_rate", 5.0),
            low_battery: m
                .param("low_battery")
                .unit("V")
                .range(0.0, 60.0)
                .default(22.0)
                .build(),
            context: None,
        }
    }
}

fn speed(m: &mut Setup<'_>, name: &str, default: f64) -> Parameter<f64> {
    m.param(name)
        .unit("m/s")
        .range(0.0, 1.5)
        .default(default)
        .build()
}

fn rate(m: &mut Setup<'_>, name: &str, default: f64) -> Parameter<f64> {
    m.param(name)
        .unit("Hz")
        .range(1.0, 75.0)
        .default(default)
        .build()
}

impl Module for MissionContext {
    fn update(&mut self) {
        let initial = Context::of_command(self.initial_context.value()).unwrap_or(Context::Idle);
        let mut context = self.context.unwrap_or(initial);
        while let Some(command) = self.command.try_pop() {
            if let Some(asked) = Context::of_command(&command) {
                if context != Context::LowBattery {
                    context = asked;
                }
            }
        }
        let victims = self.victims.get();
        let context = context.next(
            &victims.victims,
            self.battery_voltage.get(),
            self.low_battery.get(),
        );
        if self.context == Some(context) {
            return; // parameters are driven on a change only
        }
        self.context = Some(context);
        let (speed, rate, threshold) = match context {
            Context::Idle => (0.0, self.slow_scan_rate.get(), 0.7),
            Context::Explore => (self.cruise_speed.get(), self.fast_scan_rate.get(), 0.7),
            Context::ApproachVictim => (self.careful_speed.get(), self.fast_scan_rate.get(), 0.5),
            Context::ReturnHome => (self.cruise_speed.get(), self.slow_scan_rate.get(), 0.9),
            Context::LowBattery => (self.careful_speed.get(), self.slow_scan_rate.get(), 0.9),
        };
        self.max_speed.publish(speed);
        self.laser_rate.publish(rate);
        self.detection_threshold.publish(threshold);
        self.state.publish(context.as_str().to_string());
    }
}

/// The goal that brings the robot `APPROACH_DISTANCE` before `victim`, on the side it
/// was seen from (the straight line from the robot is free: the camera saw along it).
pub fn approach_goal(robot: &Pose2D, victim: &Victim) -> Pose2D {
    let (dx, dy) = (robot.x - victim.x, robot.y - victim.y);
    let d = dx.hypot(dy);
    let theta = (-dy).atan2(-dx);
    if d <= APPROACH_DISTANCE {
        return Pose2D { theta, ..*robot };
    }
    let k = APPROACH_DISTANCE / d;
    Pose2D {
        x: victim.x + dx * k,
        y: victim.y + dy * k,
        theta,
    }
}

mod manager;
mod search;
pub use manager::MissionManager;
pub use search::{nearest_unsearched, Searched};

#[cfg(test)]
mod tests;
