//! `nav_behaviours.VelocityFusion`: the iB2C fusion of (linear, angular) commands, two
//! data ports per channel: `ferroc_std`'s pair fusion with this library's port names.

use ferroc_runtime::behaviour::{Behaviour, BehaviourOutput};
use ferroc_runtime::module::Setup;
use ferroc_std::fusion::PairFusion;

/// Fuses the velocity commands of its channels, weighted by their activities.
pub struct VelocityFusion(PairFusion);

impl Behaviour for VelocityFusion {
    const NAME: &'static str = "nav_behaviours.VelocityFusion";
    const DOC: &'static str = "iB2C fusion of (linear, angular) velocity commands";
    const FUSION: bool = true;

    fn create(m: &mut Setup<'_>) -> Self {
        VelocityFusion(PairFusion::declare(
            m,
            [("linear", "m/s"), ("angular", "rad/s")],
            ["linear", "angular"],
        ))
    }

    fn transfer(&mut self, activation: f64, _derived: &mut [f64]) -> BehaviourOutput {
        self.0.step(activation)
    }
}
