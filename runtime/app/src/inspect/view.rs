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
    /// Its ports and services that its part's ROS 2 node publishes, subscribes,
    /// offers or calls (absent when none: answers of programs before issue 29 read
    /// the same).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub ros2: Vec<Ros2View>,
}

/// A port of a module published or subscribed as a ROS 2 topic, or a service (or
/// client) of it offered (or calling) as a ROS 2 service.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Ros2View {
    /// The module's port, service or client name.
    pub port: String,
    /// `publish`, `subscribe`, `service` or `client`.
    pub role: String,
    /// The fully qualified topic or service name (`/cmd_vel`).
    pub name: String,
    /// The message type (`geometry_msgs/msg/Twist`) or service type
    /// (`std_srvs/srv/SetBool`).
    pub r#type: String,
    /// The one field of the message the port carries (`linear.x`), if not all of it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub field: Option<String>,
    /// The node (`/fragile_bot`, with its namespace).
    pub node: String,
    /// Its `ROS_DOMAIN_ID`.
    pub domain: u32,
    /// A topic's QoS (services have none here).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub qos: Option<QosView>,
}

/// A topic's QoS as ROS 2 names it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct QosView {
    /// `reliable` or `best-effort`.
    pub reliability: String,
    /// `volatile` or `transient-local`.
    pub durability: String,
    /// History depth (keep last).
    pub depth: u32,
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

/// How the values of the links a part sends to other parts travel (issue 30): per link,
/// by shared memory or by network, and the part's shared-memory pool.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TransportView {
    /// Each data link the part sends, in link order.
    pub links: Vec<LinkTransportView>,
    /// The part's shared-memory pool; absent when it has none (shared memory off or
    /// not usable here, or nothing sent to other parts).
    pub pool: Option<PoolView>,
}

/// One data link to another part and how its values went so far.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LinkTransportView {
    /// The writer's `module/port`.
    pub output: String,
    /// The reading part.
    pub to_part: String,
    /// `shared memory`, `network`, `shared memory and network` (some values each way:
    /// small ones, or a full pool), or `nothing sent yet`.
    pub by: String,
    /// Values sent in a shared-memory buffer.
    pub shared_memory: u64,
    /// Values sent as bytes over the network.
    pub network: u64,
    /// Values dropped because the pool was full.
    pub dropped: u64,
}

/// A shared-memory pool's figures.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PoolView {
    /// Its size in bytes.
    pub size: u64,
    /// Bytes held now, by values on their way or read in place by readers.
    pub used: u64,
    /// Values of at least this many encoded bytes go into the pool.
    pub threshold: u64,
    /// Buffers that came back from readers whose process is gone (killed while they
    /// held values); absent from an older part (0).
    #[serde(default)]
    pub reclaimed: u64,
    /// Buffers a gone reader still counts in that have not come back yet.
    #[serde(default)]
    pub gone_held: u64,
}
