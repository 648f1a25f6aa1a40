//! `warehouse.WheelMotor`: a CANopen motor controller in velocity mode, simulated.

use crate::timing::IO_STEP;
use ferroc_runtime::module::{In, Kind, Module, ModuleType, Out, Parameter, Setup};
use ferroc_runtime::resource::LockSlot;

/// Wheel acceleration per ampere of motor current and unit of gear ratio, in wheel
/// rpm/s: with 12 A through a 24:1 gear a 0.1 m wheel accelerates the AGV at about
/// 1 m/s².
const ACCEL_PER_AMP: f64 = 0.35;
/// Proportional gain of the controller's speed loop, A per rpm of speed error.
const SPEED_GAIN: f64 = 0.5;
/// What the controller's electronics draw at standstill, A.
const IDLE_CURRENT: f64 = 0.3;

/// The motor as the simulation sees it: wheel speed and current, with the current
/// limit bounding the acceleration.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MotorModel {
    /// Wheel revolutions per minute, in the motor's own direction.
    pub speed: f64,
    /// The current of the last step, A (including the idle current).
    pub current: f64,
}

impl MotorModel {
    /// One control period of `dt` seconds towards `target` wheel rpm: the speed loop
    /// asks for a current proportional to the error, limited to `max_current`.
    pub fn step(&mut self, target: f64, gear_ratio: f64, max_current: f64, dt: f64) {
        let target = if target.is_finite() { target } else { 0.0 };
        let error = target - self.speed;
        // min/max rather than clamp: a limit that is not a number must not panic.
        let limit = max_current.max(0.0);
        let demand = (SPEED_GAIN * error).min(limit).max(-limit);
        let change = demand * gear_ratio * ACCEL_PER_AMP * dt;
        // The loop does not overshoot: a step that would pass the target ends on it.
        self.speed = if change.abs() >= error.abs() {
            target
        } else {
            self.speed + change
        };
        self.current = demand.abs() + IDLE_CURRENT;
    }
}

/// A wheel motor on the chassis CAN bus. Every exchange with the controller (read the
/// speed and current, write the target) holds the `can_bus` lock, as the real driver
/// must: both wheels share the bus.
pub struct WheelMotor {
    measured_speed: Out<f64>,
    current: Out<f32>,
    target_speed: In<f64>,
    // The node address of a real bus; the simulation has no bus traffic to address.
    #[allow(dead_code)]
    can_id: Parameter<u8>,
    gear_ratio: Parameter<f64>,
    max_current: Parameter<f64>,
    invert: Parameter<bool>,
    can_bus: LockSlot,
    motor: MotorModel,
}

impl WheelMotor {
    /// +1, or −1 for a mirror-mounted motor: the driver turns the robot's "forward"
    /// into the motor's direction and back, so the ports always mean forward.
    fn direction(&mut self) -> f64 {
        if self.invert.get() {
            -1.0
        } else {
            1.0
        }
    }
}

impl ModuleType for WheelMotor {
    const NAME: &'static str = "warehouse.WheelMotor";
    const KIND: Kind = Kind::SenseControl;
    const DOC: &'static str = "CANopen wheel motor in velocity mode";

    fn create(m: &mut Setup<'_>) -> Self {
        WheelMotor {
            measured_speed: m.sensor_output("measured_speed").unit("rpm").build(),
            current: m.sensor_output("current").unit("A").build(),
            target_speed: m
                .controller_input("target_speed")
                .unit("rpm")
                .required()
                .build(),
            can_id: m.param("can_id").range(1.0, 127.0).build(),
            gear_ratio: m
                .param("gear_ratio")
                .range(1.0, 200.0)
                .default(20.0)
                .build(),
            max_current: m
                .param("max_current")
                .unit("A")
                .range(0.0, 60.0)
                .default(10.0)
                .build(),
            invert: m
                .param("invert")
                .default(false)
                .doc("mirror-mounted motor")
                .build(),
            can_bus: m.lock("can_bus"),
            motor: MotorModel::default(),
        }
    }
}

impl Module for WheelMotor {
    fn sense(&mut self) {
        let direction = self.direction();
        let _bus = self.can_bus.lock();
        self.measured_speed.publish(direction * self.motor.speed);
        self.current.publish(self.motor.current as f32);
    }

    fn control(&mut self) {
        let direction = self.direction();
        let target = direction * self.target_speed.get();
        let (gear, max_current) = (self.gear_ratio.get(), self.max_current.get());
        let _bus = self.can_bus.lock();
        self.motor.step(target, gear, max_current, IO_STEP);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_current_limit_bounds_the_acceleration() {
        let mut motor = MotorModel::default();
        motor.step(100.0, 24.0, 12.0, 0.01);
        // Far from the target: full current, 12 A · 24 · 0.35 rpm/s for 10 ms.
        assert!((motor.speed - 12.0 * 24.0 * ACCEL_PER_AMP * 0.01).abs() < 1e-12);
        assert!((motor.current - (12.0 + IDLE_CURRENT)).abs() < 1e-12);
        // Half the current limit: half the acceleration.
        let mut weak = MotorModel::default();
        weak.step(100.0, 24.0, 6.0, 0.01);
        assert!((weak.speed * 2.0 - motor.speed).abs() < 1e-12);
        // No current allowed: it does not move.
        let mut off = MotorModel::default();
        off.step(100.0, 24.0, 0.0, 0.01);
        assert_eq!(off.speed, 0.0);
        // Nor with a limit that is not a number (and nothing panics).
        off.step(100.0, 24.0, f64::NAN, 0.01);
        assert_eq!(off.speed, 0.0);
    }

    #[test]
    fn the_speed_settles_on_the_target_without_overshoot() {
        let mut motor = MotorModel::default();
        let mut peak: f64 = 0.0;
        for _ in 0..400 {
            motor.step(100.0, 24.0, 12.0, 0.01);
            peak = peak.max(motor.speed);
        }
        assert!((motor.speed - 100.0).abs() < 1e-3, "{motor:?}");
        assert!(peak <= 100.0);
        // Standing at the target draws only the idle current.
        assert!(motor.current < IDLE_CURRENT + 0.01);
        // And a broken command means stop.
        for _ in 0..400 {
            motor.step(f64::NAN, 24.0, 12.0, 0.01);
        }
        assert!(motor.speed.abs() < 1e-3);
    }
}
