//! `crash_course.AddNoise`: Gaussian noise on a distance.

use ferroc_runtime::module::{In, Module, ModuleType, Out, Parameter, Random, Setup};

/// Adds zero-mean Gaussian noise to a distance signal. Its numbers come from the
/// runtime's random source for this module (derived from the run seed, `--seed`, and
/// the module's path) or from its own `seed` parameter, never from a clock: a lockstep
/// run with the same seed adds the same noise.
pub struct AddNoise {
    input: In<f64>,
    output: Out<f64>,
    standard_deviation: Parameter<f64>,
    seed: Parameter<u64>,
    /// The module's stream of the run seed, as at the start (for `seed` = 0).
    from_run: Random,
    /// The numbers drawn; `None` until the first cycle or after `seed` changed.
    random: Option<Random>,
}

impl ModuleType for AddNoise {
    const NAME: &'static str = "crash_course.AddNoise";
    const DOC: &'static str = "Adds zero-mean Gaussian noise to a distance signal";

    fn create(m: &mut Setup<'_>) -> Self {
        AddNoise {
            input: m.input("input").unit("m").required().build(),
            output: m.output("output").unit("m").build(),
            standard_deviation: m
                .param("standard_deviation")
                .unit("m")
                .range(0.0, 1.0)
                .default(0.0)
                .doc("standard deviation of the added noise")
                .build(),
            seed: m
                .param("seed")
                .default(0)
                .doc("0: this module's stream of the run seed (--seed); another value seeds the noise itself")
                .build(),
            from_run: m.random(),
            random: None,
        }
    }
}

impl Module for AddNoise {
    fn update(&mut self) {
        if self.seed.changed() || self.random.is_none() {
            self.random = Some(match self.seed.get() {
                0 => self.from_run.clone(),
                seed => Random::from_seed(seed),
            });
        }
        let gauss = self.random.as_mut().map_or(0.0, Random::gaussian);
        let sd = self.standard_deviation.get();
        self.output
            .publish((self.input.get() + sd * gauss).max(0.0));
    }
}
