//! iB2C fusion behaviours, with the formulas of FINROC's `mbbFusion` (finroc.md §4.3).
//!
//! Channels j = 0..n-1 bring an activity a_j, a target rating r_j and data u_j; k is the
//! first channel of the largest activity; ι is the fusion's own activation.
//!
//! | method | data | activity | target rating |
//! |---|---|---|---|
//! | `max` (winner takes all) | u_k | a_k · ι | r_k |
//! | `weighted_average` | Σ a_j u_j / Σ a_j (plain average if all a_j = 0) | Σ a_j² / Σ a_j · ι (0 if all a_j = 0) | Σ a_j r_j / Σ a_j (average if all a_j = 0) |
//! | `weighted_sum` | Σ (a_j / a_max) u_j (zero if a_max = 0) | min(1, Σ a_j² / a_max) · ι | as `weighted_average` |
//!
//! [`weigh`] computes the data weights, activity and target rating; [`fuse`] applies
//! the weights to any data type implementing [`Fuse`]. [`FusionChannels`] declares a
//! fusion's parameters (`channels`, `method`) and channel meta inputs, [`FusionOf`]
//! adds one data input per channel and the output, and [`Fusion`] is
//! `ferroc_std.Fusion`, the fusion of `f64` data. A library fusion of several data
//! ports per channel uses [`FusionChannels`] and [`fuse`] directly.

#[cfg(test)]
mod tests;

use ferroc_runtime::behaviour::{Behaviour, BehaviourOutput};
use ferroc_runtime::module::{CopyKind, In, MetaType, Out, Parameter, PortValue, Setup};
use ferroc_runtime::port::NoUninit;

/// Data a fusion can combine: a default (zero) value and a weighted sum.
///
/// Implemented for `f64`, `f32` and fixed arrays of them; a library type opts in by
/// implementing `add_weighted` field by field.
pub trait Fuse: Default {
    /// `self += weight · x`.
    fn add_weighted(&mut self, x: &Self, weight: f64);
}

impl Fuse for f64 {
    fn add_weighted(&mut self, x: &Self, weight: f64) {
        *self += weight * x;
    }
}

impl Fuse for f32 {
    fn add_weighted(&mut self, x: &Self, weight: f64) {
        *self = (*self as f64 + weight * *x as f64) as f32;
    }
}

impl<T: Fuse, const N: usize> Fuse for [T; N]
where
    [T; N]: Default,
{
    fn add_weighted(&mut self, x: &Self, weight: f64) {
        for (a, b) in self.iter_mut().zip(x) {
            a.add_weighted(b, weight);
        }
    }
}

/// How the channels are combined (parameter `method`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FusionMethod {
    /// Winner takes all: the channel of the largest activity (the first of equals).
    Max,
    /// Activity-weighted average.
    WeightedAverage,
    /// Sum weighted by activity relative to the largest.
    WeightedSum,
}

impl FusionMethod {
    /// Parses the model spelling (`max`, `weighted_average`, `weighted_sum`).
    pub fn parse(text: &str) -> Option<Self> {
        match text {
            "max" => Some(FusionMethod::Max),
            "weighted_average" => Some(FusionMethod::WeightedAverage),
            "weighted_sum" => Some(FusionMethod::WeightedSum),
            _ => None,
        }
    }
}

/// The weights of the channels' data (written into `weights`, one per channel) and the
/// fused activity and target rating, for the fusion's activation `activation`.
/// `activities`, `ratings` and `weights` have one entry per channel (the shortest
/// length counts). No channels: activity 0, target rating 0.
pub fn weigh(
    method: FusionMethod,
    activation: f64,
    activities: &[f64],
    ratings: &[f64],
    weights: &mut [f64],
) -> BehaviourOutput {
    let n = activities.len().min(ratings.len()).min(weights.len());
    let (a, r, w) = (&activities[..n], &ratings[..n], &mut weights[..n]);
    if n == 0 {
        return BehaviourOutput::default();
    }
    // k: the first channel of the largest activity.
    let mut k = 0;
    for j in 1..n {
        if a[j] > a[k] {
            k = j;
        }
    }
    let a_max = a[k];
    let sum: f64 = a.iter().sum();
    let squares: f64 = a.iter().map(|x| x * x).sum();
    let average_rating = || r.iter().sum::<f64>() / n as f64;
    let weighted_rating = || a.iter().zip(r).map(|(x, y)| x * y).sum::<f64>() / sum;
    match method {
        FusionMethod::Max => {
            w.fill(0.0);
            w[k] = 1.0;
            BehaviourOutput {
                activity: a_max * activation,
                target_rating: r[k],
            }
        }
        FusionMethod::WeightedAverage if sum > 0.0 => {
            for (w, x) in w.iter_mut().zip(a) {
                *w = x / sum;
            }
            BehaviourOutput {
                activity: squares / sum * activation,
                target_rating: weighted_rating(),
            }
        }
        FusionMethod::WeightedAverage => {
            w.fill(1.0 / n as f64);
            BehaviourOutput {
                activity: 0.0,
                target_rating: average_rating(),
            }
        }
        FusionMethod::WeightedSum if a_max > 0.0 => {
            for (w, x) in w.iter_mut().zip(a) {
                *w = x / a_max;
            }
            BehaviourOutput {
                activity: (squares / a_max).min(1.0) * activation,
                target_rating: if sum > 0.0 {
                    weighted_rating()
                } else {
                    average_rating()
                },
            }
        }
        FusionMethod::WeightedSum => {
            w.fill(0.0);
            BehaviourOutput {
                activity: 0.0,
                target_rating: average_rating(),
            }
        }
    }
}

/// Σ weight_j · data_j, starting from the default value; channels of weight 0 are
/// skipped (so a non-finite value there does not spoil the result).
pub fn fuse<T: Fuse>(weights: &[f64], data: impl IntoIterator<Item = T>) -> T {
    let mut out = T::default();
    for (w, x) in weights.iter().zip(data) {
        if *w != 0.0 {
            out.add_weighted(&x, *w);
        }
    }
    out
}

/// Channels a fusion may have at most (the compiler's bound too).
pub const MAX_CHANNELS: u32 = 1024;

/// A fusion's parameters `channels` and `method` and its channels' meta inputs
/// `in/k/activity`, `in/k/target_rating` (declare the data inputs `in/k/<name>` with
/// [`FusionChannels::port_name`]).
pub struct FusionChannels {
    method_param: Parameter<String>,
    method: FusionMethod,
    activity: Vec<In<f64>>,
    target_rating: Vec<In<f64>>,
    a: Vec<f64>,
    r: Vec<f64>,
    w: Vec<f64>,
}

impl FusionChannels {
    /// Declares the parameters and the channels' meta inputs.
    pub fn declare(m: &mut Setup<'_>) -> Self {
        let mut channels: Parameter<u32> = m
            .param("channels")
            .default(2)
            .doc("number of channels")
            .build();
        let n = channels.get().min(MAX_CHANNELS) as usize;
        let mut method_param: Parameter<String> = m
            .param("method")
            .choices(&["max", "weighted_average", "weighted_sum"])
            .default("max".to_owned())
            .doc("how the channels are combined")
            .build();
        let method = FusionMethod::parse(method_param.value()).unwrap_or(FusionMethod::Max);
        let activity = (0..n)
            .map(|k| m.meta_input(&Self::port_name(k, "activity"), MetaType::Activity))
            .collect();
        let target_rating = (0..n)
            .map(|k| m.meta_input(&Self::port_name(k, "target_rating"), MetaType::TargetRating))
            .collect();
        FusionChannels {
            method_param,
            method,
            activity,
            target_rating,
            a: vec![0.0; n],
            r: vec![0.0; n],
            w: vec![0.0; n],
        }
    }

    /// The name of channel `k`'s port `name`: `in/k/name`.
    pub fn port_name(k: usize, name: &str) -> String {
        format!("in/{k}/{name}")
    }

    /// The number of channels.
    pub fn len(&self) -> usize {
        self.a.len()
    }

    /// Whether there are no channels.
    pub fn is_empty(&self) -> bool {
        self.a.is_empty()
    }

    /// The method in use (the parameter may change while running).
    pub fn method(&self) -> FusionMethod {
        self.method
    }

    /// Reads the channels' activities and target ratings and weighs them
    /// ([`weigh`]); the data weights are then in [`weights`](Self::weights).
    pub fn weigh(&mut self, activation: f64) -> BehaviourOutput {
        if self.method_param.changed() {
            self.method = FusionMethod::parse(self.method_param.value()).unwrap_or(self.method);
        }
        for (x, port) in self.a.iter_mut().zip(&self.activity) {
            *x = port.get();
        }
        for (x, port) in self.r.iter_mut().zip(&self.target_rating) {
            *x = port.get();
        }
        weigh(self.method, activation, &self.a, &self.r, &mut self.w)
    }

    /// The data weights of the last [`weigh`](Self::weigh), one per channel.
    pub fn weights(&self) -> &[f64] {
        &self.w
    }

    /// The channels' activities as last read.
    pub fn activities(&self) -> &[f64] {
        &self.a
    }
}

/// A fusion of one data port per channel, of any copy type that can be fused.
pub struct FusionOf<T: PortValue<Kind = CopyKind> + Fuse + NoUninit> {
    /// The channels' meta inputs and parameters.
    pub channels: FusionChannels,
    inputs: Vec<In<T>>,
    output: Out<T>,
}

impl<T: PortValue<Kind = CopyKind> + Fuse + NoUninit> FusionOf<T> {
    /// Declares the channels, their data inputs `in/k/<data>` and the output `out`,
    /// all in `unit` if given.
    pub fn declare(m: &mut Setup<'_>, data: &str, out: &str, unit: Option<&str>) -> Self {
        let channels = FusionChannels::declare(m);
        let inputs = (0..channels.len())
            .map(|k| {
                let decl = m.input(&FusionChannels::port_name(k, data));
                match unit {
                    Some(u) => decl.unit(u).build(),
                    None => decl.build(),
                }
            })
            .collect();
        let decl = m.output(out);
        let output = match unit {
            Some(u) => decl.unit(u).build(),
            None => decl.build(),
        };
        FusionOf {
            channels,
            inputs,
            output,
        }
    }

    /// One cycle: weigh, fuse and publish the data; returns activity and target rating.
    pub fn step(&mut self, activation: f64) -> BehaviourOutput {
        let out = self.channels.weigh(activation);
        let fused = fuse(self.channels.weights(), self.inputs.iter().map(In::get));
        self.output.publish(fused);
        out
    }
}

/// A fusion of two `f64` data ports per channel fused with the same weights, such as a
/// velocity command's linear and angular parts: `in/k/<first>`, `in/k/<second>` → the
/// outputs `out` names. Libraries' velocity fusions are this with their port names.
pub struct PairFusion {
    /// The channels' meta inputs and parameters.
    pub channels: FusionChannels,
    inputs: Vec<[In<f64>; 2]>,
    outputs: [Out<f64>; 2],
}

/// A data port of a [`PairFusion`]: its name and unit.
pub type PortName<'a> = (&'a str, &'a str);

impl PairFusion {
    /// Declares the channels, their data inputs `in/k/<data[i].0>` and the outputs
    /// `out[i].0`, each pair in the unit of `data[i]`.
    pub fn declare(m: &mut Setup<'_>, data: [PortName<'_>; 2], out: [&str; 2]) -> Self {
        let channels = FusionChannels::declare(m);
        let inputs = (0..channels.len())
            .map(|k| {
                data.map(|(name, unit)| {
                    m.input(&FusionChannels::port_name(k, name))
                        .unit(unit)
                        .build()
                })
            })
            .collect();
        let outputs = [0, 1].map(|i| m.output(out[i]).unit(data[i].1).build());
        PairFusion {
            channels,
            inputs,
            outputs,
        }
    }

    /// One cycle: weigh, fuse both parts with the same weights and publish them;
    /// returns activity and target rating.
    pub fn step(&mut self, activation: f64) -> BehaviourOutput {
        let out = self.channels.weigh(activation);
        let fused = fuse(
            self.channels.weights(),
            self.inputs.iter().map(|[a, b]| [a.get(), b.get()]),
        );
        for (port, value) in self.outputs.iter_mut().zip(fused) {
            port.publish(value);
        }
        out
    }
}

/// `ferroc_std.Fusion`: the iB2C fusion of `f64` data (`in/k/value` → `value`).
pub struct Fusion(FusionOf<f64>);

impl Behaviour for Fusion {
    const NAME: &'static str = "ferroc_std.Fusion";
    const DOC: &'static str = "iB2C fusion of f64 values: max, weighted average or weighted sum";
    const FUSION: bool = true;

    fn create(m: &mut Setup<'_>) -> Self {
        Fusion(FusionOf::declare(m, "value", "value", None))
    }

    fn transfer(&mut self, activation: f64, _derived: &mut [f64]) -> BehaviourOutput {
        self.0.step(activation)
    }
}
