//! `crash_course.AddNoise`: Gaussian noise on a distance.

use ferroc_runtime::module::{In, Module, ModuleType, Out, Parameter, Setup};

/// Adds zero-mean Gaussian noise to a distance signal.
pub struct AddNoise {
    input: In<f64>,
    output: Out<f64>,
    standard_deviation: Parameter<f64>,
    seed: Parameter<u64>,
    state: u64,
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
                .doc("0 seeds from the system clock")
                .build(),
            state: 0,
        }
    }
}

impl AddNoise {
    /// xorshift64*: plenty for sensor noise, and no dependency.
    fn next_unit(&mut self) -> f64 {
        if self.state == 0 || self.seed.changed() {
            self.state = match self.seed.get() {
                0 => {
                    std::time::SystemTime::now()
                        .duration_since(std::time::UNIX_EPOCH)
                        .map_or(1, |d| d.as_nanos() as u64)
                        | 1
                }
                seed => seed,
            };
        }
        self.state ^= self.state >> 12;
        self.state ^= self.state << 25;
        self.state ^= self.state >> 27;
        let r = self.state.wrapping_mul(0x2545_F491_4F6C_DD1D);
        ((r >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
}

impl Module for AddNoise {
    fn update(&mut self) {
        let sd = self.standard_deviation.get();
        // Box–Muller.
        let (u1, u2) = (self.next_unit(), self.next_unit());
        let gauss = (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
        self.output
            .publish((self.input.get() + sd * gauss).max(0.0));
    }
}
