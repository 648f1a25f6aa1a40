//! What an inspector answers, in serde form: the same structs are the JSON payloads
//! of the Zenoh keys (docs/inspect.md) and what `ferroc inspect` reads back.

use serde::{Deserialize, Serialize};

/// The element tree of (a part of) an application.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Tree {
    /// The modules, in the order they were built (the model's order).
    pub modules: Vec<ModuleView>,
    /// The thread containers and the modules each executes.
    pub containers: Vec<ContainerTree>,
}

/// One module instance.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModuleView {
    /// Element path (`robot/control/avoid`).
    pub path: String,
    /// The module type (`nav_behaviours.AvoidObstacles`).
    pub r#type: String,
    /// `plain`, `sense-control`, `behaviour` or `fusion`.
    pub kind: String,
    /// The part (process) it belongs to.
    pub part: String,
    /// Where the model declares it (`FILE:LINE:COL`), when the runner knows.
    pub source: Option<String>,
    /// The thread container executing it.
    pub container: Option<String>,
    /// Its ports.
    pub ports: Vec<PortView>,
    /// Its parameters with their current values.
    pub params: Vec<ParamView>,
}

/// One port of a module.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PortView {
    /// Port name.
    pub name: String,
    /// `in` or `out`.
    pub dir: String,
    /// The model type of its values.
    pub r#type: String,
    /// Unit of its values.
    pub unit: Option<String>,
    /// iB2C meta port (stimulation, inhibition, activity, target rating).
    pub meta: bool,
    /// For an input: the outputs (`module/port`) that feed it.
    pub from: Vec<String>,
}

/// One parameter, with its declaration and current value.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ParamView {
    /// The module's path.
    pub module: String,
    /// Parameter name.
    pub name: String,
    /// The model type (`f64`, `duration`, `string`).
    pub r#type: String,
    /// The unit its value is in.
    pub unit: Option<String>,
    /// Smallest allowed value.
    pub min: Option<f64>,
    /// Largest allowed value.
    pub max: Option<f64>,
    /// Allowed values of a string parameter.
    pub choices: Vec<String>,
    /// The current value as a manifest writes it (in `unit`).
    pub value: String,
}

/// A thread container and its modules.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ContainerTree {
    /// Element path.
    pub path: String,
    /// The modules it executes, in step order.
    pub modules: Vec<String>,
}

/// The latest value of a port.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PortValue {
    /// `module/port` of the output the value was read from.
    pub port: String,
    /// The model type.
    pub r#type: String,
    /// Unit of the value.
    pub unit: Option<String>,
    /// False while the output still holds its initial value (nothing published yet).
    pub published: bool,
    /// The value in its serde (JSON) form; non-finite floats are `null`.
    pub value: serde_json::Value,
}

/// The figures of a thread container.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ContainerView {
    /// Element path.
    pub path: String,
    /// Cycles completed.
    pub cycles: u64,
    /// Cycles that missed their deadline.
    pub overruns: u64,
    /// Average share of the period spent executing.
    pub load: f64,
    /// Mean cycle time, microseconds.
    pub mean_cycle_us: f64,
    /// The latest cycle's time, microseconds.
    pub last_cycle_us: f64,
    /// Each step's figures, in schedule order.
    pub steps: Vec<StepView>,
    /// Messages of steps that panicked (and were stopped).
    pub panics: Vec<String>,
}

/// The figures of one step.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StepView {
    /// `module/path:update` (or `:sense`, `:control`).
    pub name: String,
    /// Executions so far.
    pub runs: u64,
    /// Mean execution time, microseconds.
    pub mean_us: f64,
    /// Longest execution time, microseconds.
    pub max_us: f64,
}

/// The state of an input fed by a link from another part.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LinkView {
    /// `module/input` of the reader.
    pub input: String,
    /// `up` (values arrive), `waiting` (none yet), `stale` (older than the link's
    /// deadline) or `gone` (the writer's part is gone).
    pub state: String,
    /// Milliseconds since the latest value arrived.
    pub age_ms: Option<f64>,
}

/// The iB2C meta signals of a behaviour.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ActivityView {
    /// The behaviour's path.
    pub module: String,
    /// Its activity output `a` (0 before the first cycle).
    pub activity: Option<f64>,
    /// Its target rating `r`.
    pub target_rating: Option<f64>,
}
