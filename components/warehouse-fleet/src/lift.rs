//! `warehouse.Lift`: the shelf lift with its load sensor, simulated.

use crate::timing::IO_STEP;
use ferroc_runtime::module::{In, Kind, Module, ModuleType, Out, Parameter, Setup};

/// Where the lift is going, from its height and the command.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LiftMotion {
    /// At the bottom: the shelf (if any) stands on the floor.
    #[default]
    Lowered,
    Raising,
    /// At the top, carrying the shelf.
    Raised,
    Lowering,
}

/// The lift mechanism: a height moving at a fixed speed between 0 and the top.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LiftState {
    /// Metres above the lowest position.
    pub height: f64,
    pub motion: LiftMotion,
    /// The shelf rests on the lift: from reaching the top until it is back on the floor.
    pub carrying: bool,
}

impl LiftState {
    /// One step of `dt` seconds with the command `raise`.
    pub fn step(&mut self, raise: bool, top: f64, speed: f64, dt: f64) {
        let target = if raise { top } else { 0.0 };
        let travel = speed * dt;
        self.height = if (target - self.height).abs() <= travel {
            target
        } else if target > self.height {
            self.height + travel
        } else {
            self.height - travel
        };
        self.motion = match (raise, self.height == target) {
            (true, true) => LiftMotion::Raised,
            (true, false) => LiftMotion::Raising,
            (false, true) => LiftMotion::Lowered,
            (false, false) => LiftMotion::Lowering,
        };
        // With a top of 0 there is nothing to lift the shelf with.
        if self.motion == LiftMotion::Raised && top > 0.0 {
            self.carrying = true;
        } else if self.height <= 0.0 {
            self.carrying = false;
        }
    }

    /// The load sensor: weight on the lift.
    pub fn loaded(&self) -> bool {
        self.carrying
    }
}

/// The shelf lift of one AGV: `raise` lifts the shelf above it, false sets it down.
pub struct Lift {
    height: Out<f64>,
    loaded: Out<bool>,
    raise: In<bool>,
    max_height: Parameter<f64>,
    lift_speed: Parameter<f64>,
    state: LiftState,
}

impl ModuleType for Lift {
    const NAME: &'static str = "warehouse.Lift";
    const KIND: Kind = Kind::SenseControl;
    const DOC: &'static str = "Shelf lift with load detection";

    fn create(m: &mut Setup<'_>) -> Self {
        Lift {
            height: m.sensor_output("height").unit("m").build(),
            loaded: m.sensor_output("loaded").build(),
            raise: m.controller_input("raise").required().build(),
            max_height: m
                .param("max_height")
                .unit("m")
                .range(0.0, 0.5)
                .default(0.06)
                .build(),
            lift_speed: m
                .param("lift_speed")
                .unit("m/s")
                .range(0.001, 0.2)
                .default(0.02)
                .build(),
            state: LiftState::default(),
        }
    }
}

impl Module for Lift {
    fn sense(&mut self) {
        self.height.publish(self.state.height);
        self.loaded.publish(self.state.loaded());
    }

    fn control(&mut self) {
        let raise = *self.raise.get();
        let (top, speed) = (self.max_height.get(), self.lift_speed.get());
        self.state.step(raise, top, speed, IO_STEP);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn raising_and_lowering_go_through_every_state() {
        let mut lift = LiftState::default();
        assert_eq!(lift.motion, LiftMotion::Lowered);
        // 6 cm at 2 cm/s: three seconds, 300 steps of 10 ms.
        lift.step(true, 0.06, 0.02, 0.01);
        assert_eq!(lift.motion, LiftMotion::Raising);
        assert!(!lift.loaded());
        let mut steps = 1;
        while lift.motion == LiftMotion::Raising {
            lift.step(true, 0.06, 0.02, 0.01);
            steps += 1;
            assert!(lift.height <= 0.06 && steps < 1000);
        }
        assert_eq!(lift.motion, LiftMotion::Raised);
        assert!((299..=301).contains(&steps), "{steps}");
        assert!(lift.loaded());
        // Half way down the shelf still rests on the lift.
        for _ in 0..150 {
            lift.step(false, 0.06, 0.02, 0.01);
        }
        assert_eq!(lift.motion, LiftMotion::Lowering);
        assert!(lift.loaded());
        assert!((lift.height - 0.03).abs() < 1e-9);
        // Raising again from there keeps it; down on the floor it is off.
        lift.step(true, 0.06, 0.02, 0.01);
        assert_eq!(lift.motion, LiftMotion::Raising);
        assert!(lift.loaded());
        for _ in 0..200 {
            lift.step(false, 0.06, 0.02, 0.01);
        }
        assert_eq!(lift.motion, LiftMotion::Lowered);
        assert_eq!(lift.height, 0.0);
        assert!(!lift.loaded());
    }

    #[test]
    fn a_lift_without_travel_never_carries() {
        let mut lift = LiftState::default();
        lift.step(true, 0.0, 0.02, 0.01);
        assert_eq!(lift.motion, LiftMotion::Raised);
        assert!(!lift.loaded());
    }
}
