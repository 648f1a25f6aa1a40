//! `warehouse.BatteryMonitor`: the bridge to the battery management system, simulated
//! as a LiFePO4 pack draining at the AGV's average consumption.

use crate::timing::IO_STEP;
use ferroc_runtime::console;
use ferroc_runtime::module::{Module, ModuleType, Out, Parameter, Setup};

/// State of charge when the simulation starts.
const INITIAL_CHARGE: f64 = 0.95;
/// Average drain of a working AGV: a full pack lasts about eight hours.
const DRAIN_PER_SECOND: f64 = 1.0 / (8.0 * 3600.0);
/// LiFePO4 cell voltage: nearly flat between empty and full.
const CELL_EMPTY_VOLTS: f64 = 3.0;
const CELL_FULL_VOLTS: f64 = 3.35;

/// The pack: its state of charge and the voltage that goes with it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BatteryModel {
    /// 0 .. 1.
    pub charge: f64,
}

impl Default for BatteryModel {
    fn default() -> Self {
        BatteryModel {
            charge: INITIAL_CHARGE,
        }
    }
}

impl BatteryModel {
    /// Drains the pack for `dt` seconds (never below empty).
    pub fn drain(&mut self, dt: f64) {
        self.charge = (self.charge - DRAIN_PER_SECOND * dt).max(0.0);
    }

    /// Terminal voltage of a pack of `cells` cells in series.
    pub fn voltage(&self, cells: u8) -> f64 {
        f64::from(cells) * (CELL_EMPTY_VOLTS + (CELL_FULL_VOLTS - CELL_EMPTY_VOLTS) * self.charge)
    }
}

/// The battery management system of one AGV. The simulated pack is not charged (there
/// is no charger in the simulation), so `charging` stays false; it warns once when the
/// charge falls below `low_charge`.
pub struct BatteryMonitor {
    voltage: Out<f64>,
    charge: Out<f32>,
    charging: Out<bool>,
    cells: Parameter<u8>,
    low_charge: Parameter<f64>,
    pack: BatteryModel,
    warned: bool,
}

impl ModuleType for BatteryMonitor {
    const NAME: &'static str = "warehouse.BatteryMonitor";
    const DOC: &'static str = "Battery management system bridge";

    fn create(m: &mut Setup<'_>) -> Self {
        BatteryMonitor {
            voltage: m.output("voltage").unit("V").build(),
            charge: m.output("charge").doc("state of charge, 0 .. 1").build(),
            charging: m.output("charging").build(),
            cells: m.param("cells").range(1.0, 32.0).build(),
            low_charge: m.param("low_charge").range(0.0, 1.0).default(0.2).build(),
            pack: BatteryModel::default(),
            warned: false,
        }
    }
}

impl Module for BatteryMonitor {
    fn update(&mut self) {
        self.pack.drain(IO_STEP);
        let cells = self.cells.get();
        self.voltage.publish(self.pack.voltage(cells));
        self.charge.publish(self.pack.charge as f32);
        self.charging.publish(false);
        if !self.warned && self.pack.charge < self.low_charge.get() {
            self.warned = true;
            console::line(&format!(
                "[battery] charge {:.0}% is below the low mark",
                self.pack.charge * 100.0
            ));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pack_drains_and_its_voltage_follows() {
        let mut pack = BatteryModel::default();
        let full = pack.voltage(16);
        assert!((full - 16.0 * (3.0 + 0.35 * 0.95)).abs() < 1e-9);
        // One hour of work: an eighth of the pack.
        for _ in 0..3600 {
            pack.drain(1.0);
        }
        assert!((pack.charge - (0.95 - 0.125)).abs() < 1e-9);
        assert!(pack.voltage(16) < full);
        // It never goes below empty.
        pack.drain(1e9);
        assert_eq!(pack.charge, 0.0);
        assert!((pack.voltage(16) - 48.0).abs() < 1e-9);
    }
}
