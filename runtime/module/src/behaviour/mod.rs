//! iB2C behaviours: a hand-written behaviour implements its transfer function, activity
//! and target rating; the behaviour base does everything every behaviour shares.
//!
//! ```
//! use ferroc_module::behaviour::{Behaviour, BehaviourOutput};
//! use ferroc_module::{In, Out, Setup};
//!
//! /// Drives forward, slower the closer the obstacle; content when nothing is near.
//! struct Cruise { distance: In<f64>, speed: Out<f64> }
//!
//! impl Behaviour for Cruise {
//!     const NAME: &'static str = "demo.Cruise";
//!     fn create(m: &mut Setup<'_>) -> Self {
//!         Cruise {
//!             distance: m.input("distance").unit("m").build(),
//!             speed: m.output("speed").unit("m/s").build(),
//!         }
//!     }
//!     fn transfer(&mut self, activation: f64, _derived: &mut [f64]) -> BehaviourOutput {
//!         let near = (1.0 - self.distance.get()).clamp(0.0, 1.0);
//!         self.speed.publish(0.5 * (1.0 - near));
//!         BehaviourOutput { activity: activation * (1.0 - near), target_rating: near }
//!     }
//! }
//! ```
//!
//! Registered with `registry.register_behaviour::<Cruise>()`, it is an ordinary module
//! type (its [`Kind`] is `Behaviour` or `Fusion`) whose interface has, besides what its
//! `create` declares, the meta ports the compiler gives every behaviour: `stimulation`,
//! `inhibition/0..n-1` (n = the instance parameter `inhibitions`), `activity`,
//! `target_rating`, `activity/<derived>` per [`Behaviour::DERIVED`], and the parameter
//! `stimulation_mode` (`auto`, `enabled`, `disabled`).
//!
//! Every cycle the base computes the activation ι = s · (1 − max over connected
//! inhibitions) (s is 1 / 0 in the modes `enabled` / `disabled`, the stimulation input in
//! `auto`, 0 if that input is unconnected), calls [`Behaviour::transfer`], checks the
//! principles ([`Rule`]) and publishes activity, target rating and derived activities.
//! A violation is handled by the instance's [`ViolationPolicy`].

mod principles;
#[cfg(test)]
mod tests;

pub use crate::violations::{
    ModuleViolations, Rule, ViolationCount, ViolationLog, ViolationPolicy, WARN_EVERY_CYCLES,
};
pub use principles::{activation, TOLERANCE};

use crate::violations::Monitor;
use crate::{In, Kind, MetaType, Module, ModuleType, Out, Parameter, Setup, StopStep};
use ferroc_ports::port::CopyPeek;
use principles::{check_range, Cycle, Principles};

/// What a behaviour computed in one cycle.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BehaviourOutput {
    /// How much it acts, in [0, activation].
    pub activity: f64,
    /// How discontent it is, in [0, 1]: 0 goal reached.
    pub target_rating: f64,
}

/// A hand-written iB2C behaviour: its data ports and parameters, and what it does.
pub trait Behaviour: Send + Sized + 'static {
    /// Qualified model name (`nav_behaviours.GoToGoal`).
    const NAME: &'static str;
    /// One-line description.
    const DOC: &'static str = "";
    /// A fusion behaviour (`kind="fusion"`): its `create` declares the channels (see
    /// `ferroc_std::fusion`).
    const FUSION: bool = false;
    /// The derived activities, in manifest order: outputs `activity/<name>`.
    const DERIVED: &'static [&'static str] = &[];

    /// Declares the data ports and own parameters (the base declares the meta ports).
    fn create(m: &mut Setup<'_>) -> Self;

    /// One cycle for the activation ι: read inputs, publish data outputs, return
    /// activity and target rating; write the derived activities (zeroed before the
    /// call) into `derived`, one per [`Self::DERIVED`] name.
    fn transfer(&mut self, activation: f64, derived: &mut [f64]) -> BehaviourOutput;
}

/// How the stimulation is obtained.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StimulationMode {
    /// From the `stimulation` input (0 if it is not connected).
    Auto,
    /// Always 1.
    Enabled,
    /// Always 0.
    Disabled,
}

impl StimulationMode {
    fn parse(text: &str) -> Self {
        match text {
            "enabled" => StimulationMode::Enabled,
            "disabled" => StimulationMode::Disabled,
            _ => StimulationMode::Auto,
        }
    }
}

/// Inhibition ports an instance may have at most (the compiler's bound too).
pub const MAX_INHIBITIONS: u32 = 1024;

/// The behaviour base: a [`Behaviour`] as a module type.
pub struct BehaviourModule<B: Behaviour> {
    inner: B,
    stimulation: In<f64>,
    inhibitions: Vec<In<f64>>,
    /// Whether each meta input has a source; learned in the first cycle (connections
    /// are made before the application starts).
    wiring: Option<(bool, Vec<bool>)>,
    mode_param: Parameter<String>,
    mode: StimulationMode,
    activity: Out<f64>,
    target_rating: Out<f64>,
    derived_out: Vec<Out<f64>>,
    derived: Vec<f64>,
    activity_inputs: Vec<(CopyPeek<f64>, f64)>,
    principles: Principles,
    monitor: Monitor,
}

impl<B: Behaviour> BehaviourModule<B> {
    /// The behaviour inside (for tests and introspection).
    pub fn inner(&self) -> &B {
        &self.inner
    }

    fn learn_wiring(&mut self) -> (bool, &[bool]) {
        let (s, i) = self.wiring.get_or_insert_with(|| {
            (
                self.stimulation.port.connection_count() > 0,
                self.inhibitions
                    .iter()
                    .map(|i| i.port.connection_count() > 0)
                    .collect(),
            )
        });
        (*s, i)
    }

    /// The activation of this cycle, the inputs' ranges checked.
    fn compute_activation(&mut self) -> f64 {
        if self.mode_param.changed() {
            self.mode = StimulationMode::parse(self.mode_param.value());
        }
        let (stimulation_connected, _) = self.learn_wiring();
        let mut s = match self.mode {
            StimulationMode::Enabled => 1.0,
            StimulationMode::Disabled => 0.0,
            StimulationMode::Auto if stimulation_connected => self.stimulation.get(),
            StimulationMode::Auto => 0.0,
        };
        check_range(&mut self.monitor, "stimulation", &mut s);
        let mut inhibition = 0.0_f64;
        let connected = self.wiring.as_ref().map_or(&[][..], |(_, i)| &i[..]);
        for (k, (port, on)) in self.inhibitions.iter().zip(connected).enumerate() {
            if !on {
                continue;
            }
            let mut i = port.get();
            check_range(&mut self.monitor, format_args!("inhibition/{k}"), &mut i);
            inhibition = inhibition.max(i);
        }
        activation(s, [inhibition])
    }

    fn activity_input_changed(&mut self) -> bool {
        let mut changed = false;
        for (peek, last) in &mut self.activity_inputs {
            let now = peek.get();
            if now.to_bits() != last.to_bits() {
                *last = now;
                changed = true;
            }
        }
        changed
    }
}

impl<B: Behaviour> Module for BehaviourModule<B> {
    fn update(&mut self) {
        self.monitor.next_cycle();
        let iota = self.compute_activation();
        let changed = self.activity_input_changed();
        self.derived.fill(0.0);
        let out = self.inner.transfer(iota, &mut self.derived);
        let mut cycle = Cycle {
            activation: iota,
            activity: out.activity,
            target_rating: out.target_rating,
            derived: &mut self.derived,
            activity_input_changed: changed,
        };
        self.principles
            .check(&mut cycle, B::DERIVED, &mut self.monitor);
        let (a, r) = (cycle.activity, cycle.target_rating);
        if let Some(why) = self.monitor.stop.take() {
            // Like a panic, without the panic hook's noise: the container catches it,
            // reports it with the step's name and stops this step.
            std::panic::resume_unwind(Box::new(StopStep(why)));
        }
        self.activity.publish(a);
        self.target_rating.publish(r);
        for (port, value) in self.derived_out.iter().zip(&self.derived) {
            port.publish(*value);
        }
    }
}

impl<B: Behaviour> ModuleType for BehaviourModule<B> {
    const NAME: &'static str = B::NAME;
    const KIND: Kind = if B::FUSION {
        Kind::Fusion
    } else {
        Kind::Behaviour
    };
    const DOC: &'static str = B::DOC;

    fn create(m: &mut Setup<'_>) -> Self {
        let mut mode_param: Parameter<String> = m
            .param("stimulation_mode")
            .choices(&["auto", "enabled", "disabled"])
            .default("auto".to_owned())
            .doc("auto: the stimulation input; enabled: 1; disabled: 0")
            .build();
        let mut count: Parameter<u32> = m
            .param("inhibitions")
            .default(1)
            .doc("number of inhibition inputs")
            .build();
        let count = count.get().min(MAX_INHIBITIONS);
        let stimulation = m.meta_input("stimulation", MetaType::Stimulation);
        let inhibitions = (0..count)
            .map(|k| m.meta_input(&format!("inhibition/{k}"), MetaType::Inhibition))
            .collect();
        let activity = m.meta_output("activity", MetaType::Activity);
        let target_rating = m.meta_output("target_rating", MetaType::TargetRating);
        let derived_out = B::DERIVED
            .iter()
            .map(|d| m.meta_output(&format!("activity/{d}"), MetaType::Activity))
            .collect();
        let inner = B::create(m);
        let activity_inputs = std::mem::take(&mut m.activity_inputs)
            .into_iter()
            .map(|p| (p, f64::NAN))
            .collect();
        let monitor = Monitor::new(m.path(), m.policy, m.log.clone());
        BehaviourModule {
            mode: StimulationMode::parse(mode_param.value()),
            mode_param,
            inner,
            stimulation,
            inhibitions,
            wiring: None,
            activity,
            target_rating,
            derived_out,
            derived: vec![0.0; B::DERIVED.len()],
            activity_inputs,
            principles: Principles::default(),
            monitor,
        }
    }
}
