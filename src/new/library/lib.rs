//! The library `@name@`: the Rust code of the module types in `@name@.lib.xml`.

use ferroc_runtime::builder::Registry;
use ferroc_runtime::module::{In, Module, ModuleType, Out, Parameter, Setup};

/// Adds `gain` times its input `step` to a running total and publishes it.
pub struct Accumulator {
    step: In<f64>,
    total_out: Out<f64>,
    gain: Parameter<f64>,
    total: f64,
}

impl ModuleType for Accumulator {
    /// The model's name of the type: library, dot, module type.
    const NAME: &'static str = "@name@.Accumulator";
    const DOC: &'static str = "Adds gain times step to its total every cycle";

    /// Declares the ports and parameters (`ferroc types export` reads them from here).
    fn create(m: &mut Setup<'_>) -> Self {
        Accumulator {
            step: m.input("step").doc("added every cycle, times gain").build(),
            total_out: m.output("total").doc("the sum so far").build(),
            gain: m
                .param("gain")
                .default(1.0)
                .range(0.0, 100.0)
                .doc("factor applied to every step")
                .build(),
            total: 0.0,
        }
    }
}

impl Module for Accumulator {
    /// Runs once per cycle of the thread container the model puts it in.
    fn update(&mut self) {
        self.total = accumulate(self.total, self.step.get(), self.gain.get());
        self.total_out.publish(self.total);
        println!("[@name@] total = {:.2}", self.total);
    }
}

/// The arithmetic, kept apart from the ports so it is easy to test.
pub fn accumulate(total: f64, step: f64, gain: f64) -> f64 {
    total + gain * step
}

/// Registers the library's module types; the runner `ferroc run` builds calls this.
pub fn register(registry: &mut Registry) {
    registry.register::<Accumulator>();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_step_adds_gain_times_step() {
        let total = accumulate(0.0, 0.5, 2.0);
        assert_eq!(total, 1.0);
        assert_eq!(accumulate(total, 0.25, 4.0), 2.0);
    }

    #[test]
    fn the_registered_interface_has_the_ports_and_parameter_of_the_manifest() {
        let mut registry = Registry::new();
        register(&mut registry);
        let interface = registry.interface("@name@.Accumulator").expect("registered");
        assert!(interface.port("step").is_some());
        assert!(interface.port("total").is_some());
        assert_eq!(interface.params.len(), 1);
        assert_eq!(interface.params[0].name, "gain");
    }
}
