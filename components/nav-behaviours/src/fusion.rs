//! `nav_behaviours.VelocityFusion`: the iB2C fusion of (linear, angular) commands, two
//! data ports per channel, with `ferroc_std`'s fusion formulas.

use ferroc_runtime::behaviour::{Behaviour, BehaviourOutput};
use ferroc_runtime::module::{In, Out, Setup};
use ferroc_std::fusion::{fuse, FusionChannels};

/// Fuses the velocity commands of its channels, weighted by their activities.
pub struct VelocityFusion {
    channels: FusionChannels,
    /// Per channel: (linear, angular).
    inputs: Vec<(In<f64>, In<f64>)>,
    linear: Out<f64>,
    angular: Out<f64>,
}

impl Behaviour for VelocityFusion {
    const NAME: &'static str = "nav_behaviours.VelocityFusion";
    const DOC: &'static str = "iB2C fusion of (linear, angular) velocity commands";
    const FUSION: bool = true;

    fn create(m: &mut Setup<'_>) -> Self {
        let channels = FusionChannels::declare(m);
        let inputs = (0..channels.len())
            .map(|k| {
                (
                    m.input(&FusionChannels::port_name(k, "linear"))
                        .unit("m/s")
                        .build(),
                    m.input(&FusionChannels::port_name(k, "angular"))
                        .unit("rad/s")
                        .build(),
                )
            })
            .collect();
        VelocityFusion {
            channels,
            inputs,
            linear: m.output("linear").unit("m/s").build(),
            angular: m.output("angular").unit("rad/s").build(),
        }
    }

    fn transfer(&mut self, activation: f64, _derived: &mut [f64]) -> BehaviourOutput {
        let out = self.channels.weigh(activation);
        // Both components with the same weights: fuse them as one [linear, angular].
        let [linear, angular] = fuse(
            self.channels.weights(),
            self.inputs.iter().map(|(l, a)| [l.get(), a.get()]),
        );
        self.linear.publish(linear);
        self.angular.publish(angular);
        out
    }
}
