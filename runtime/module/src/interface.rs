//! A module type's interface as its Rust code declares it.
//!
//! Recorded while the type's `create` runs (so the declaration and the ports the module
//! really owns cannot drift apart), compared against the library manifest a model was
//! checked with, and written out by `ferroc types export`. Serde: a runner describes
//! its registered types to the `ferroc` CLI as JSON (`ferroc_runner::describe`), which
//! compares them with the manifests.

use serde::{Deserialize, Serialize};

/// How the thread container runs a module.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Kind {
    /// One `update` step per cycle.
    Plain,
    /// A `sense` step (in the sensing half of the cycle) and a `control` step.
    SenseControl,
    /// An iB2C behaviour: one `update` step per cycle, run by the behaviour base
    /// ([`crate::behaviour`]), with the meta ports every behaviour has.
    Behaviour,
    /// An iB2C fusion behaviour: a behaviour whose inputs are channels.
    Fusion,
}

impl Kind {
    /// The manifest spelling (`kind="…"`; plain modules omit it).
    pub fn as_str(self) -> &'static str {
        match self {
            Kind::Plain => "plain",
            Kind::SenseControl => "sense-control",
            Kind::Behaviour => "behaviour",
            Kind::Fusion => "fusion",
        }
    }

    /// Whether the type runs one `update` step per cycle (plain modules and behaviours).
    pub fn has_update(self) -> bool {
        !matches!(self, Kind::SenseControl)
    }
}

/// Data direction of a port.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Direction {
    /// Data flows into the module.
    In,
    /// Data flows out of the module.
    Out,
}

/// Which half of a sense-control module a port belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Role {
    /// A port of a plain module.
    Plain,
    /// Sensor data (`sensor-in` / `sensor-out`), used by the `sense` step.
    Sensor,
    /// Controller data (`controller-in` / `controller-out`), used by the `control` step.
    Controller,
    /// An iB2C meta port (stimulation, inhibition, activity, target rating, fusion
    /// channel meta inputs): manifests do not declare these, the behaviour kind implies
    /// them.
    Meta,
}

/// The iB2C meta signal types: numbers in [0, 1] that travel as `f64`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MetaType {
    /// How much a behaviour is allowed to act (input).
    Stimulation,
    /// How much a behaviour is suppressed (input).
    Inhibition,
    /// How much a behaviour acts (output, and activity inputs of fusions).
    Activity,
    /// How discontent a behaviour is: 0 goal reached, 1 maximally discontent.
    TargetRating,
}

impl MetaType {
    /// The type's model name (`Activity`).
    pub fn as_str(self) -> &'static str {
        match self {
            MetaType::Stimulation => "Stimulation",
            MetaType::Inhibition => "Inhibition",
            MetaType::Activity => "Activity",
            MetaType::TargetRating => "TargetRating",
        }
    }
}

impl Role {
    /// The manifest element for a port of this role and direction.
    pub fn element(self, dir: Direction) -> &'static str {
        match (self, dir) {
            (Role::Plain, Direction::In) => "in",
            (Role::Plain, Direction::Out) => "out",
            (Role::Sensor, Direction::In) => "sensor-in",
            (Role::Sensor, Direction::Out) => "sensor-out",
            (Role::Controller, Direction::In) => "controller-in",
            (Role::Controller, Direction::Out) => "controller-out",
            (Role::Meta, Direction::In) => "meta-in",
            (Role::Meta, Direction::Out) => "meta-out",
        }
    }
}

/// One declared port.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PortInfo {
    /// Port name (unique per module).
    pub name: String,
    /// Data direction.
    pub dir: Direction,
    /// Sensor / controller half, or plain.
    pub role: Role,
    /// The value type's model name (`f64`, `nav.Pose2D`).
    pub model_type: String,
    /// Unit of the values, as written in manifests (`m/s`).
    pub unit: Option<String>,
    /// The input must be connected.
    pub required: bool,
    /// One-line description.
    pub doc: Option<String>,
}

/// One declared parameter.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ParamInfo {
    /// Parameter name (unique per module).
    pub name: String,
    /// The value type's model name.
    pub model_type: String,
    /// Unit the module expects its value in.
    pub unit: Option<String>,
    /// Smallest allowed value.
    pub min: Option<f64>,
    /// Largest allowed value.
    pub max: Option<f64>,
    /// Default value as text (none: the model must give one).
    pub default: Option<String>,
    /// Allowed values of a string parameter.
    pub choices: Vec<String>,
    /// One-line description.
    pub doc: Option<String>,
}

/// A flexible port group (`<flexible port dir same-type min-count max-count>`): the
/// instance declares its ports in the model.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct FlexibleInfo {
    /// The group's name (`in`): ports `in/0`, `in/1`, … or just `in`.
    pub group: String,
    /// Input or output.
    pub dir: Direction,
    /// All ports of one type.
    pub same_type: bool,
    /// Fewest ports an instance declares.
    pub min_count: u32,
    /// Most ports an instance declares (`None`: no limit).
    pub max_count: Option<u32>,
}

/// Everything a manifest says about a module type, as the Rust code declares it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Interface {
    /// Qualified model name (`crash_course.AddNoise`).
    pub name: String,
    /// Rust path of the implementing type.
    pub rust: String,
    /// Plain or sense-control.
    pub kind: Kind,
    /// One-line description.
    pub doc: Option<String>,
    /// Ports in declaration order.
    pub ports: Vec<PortInfo>,
    /// Parameters in declaration order.
    pub params: Vec<ParamInfo>,
    /// Flexible port groups (their ports, for an instance, are among `ports`).
    pub flexible: Vec<FlexibleInfo>,
    /// Services it answers and clients it calls with, in declaration order.
    pub services: Vec<ServiceInfo>,
}

/// One declared `<service>` (answered by the module) or `<client>` (calls one).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ServiceInfo {
    /// Name, unique among the module's ports and services.
    pub name: String,
    /// `true` for a `<client>`, `false` for a `<service>`.
    pub client: bool,
    /// Model type of the requests.
    pub request: String,
    /// Model type of the responses.
    pub response: String,
    /// Who executes a service's requests (`Server` for clients).
    #[serde(with = "executes")]
    pub executes: ferroc_ports::service::Executes,
    /// How long a client's blocking call waits (`None`: until answered).
    pub timeout: Option<std::time::Duration>,
    /// One-line description.
    pub doc: Option<String>,
}

impl Interface {
    /// The port called `name`.
    pub fn port(&self, name: &str) -> Option<&PortInfo> {
        self.ports.iter().find(|p| p.name == name)
    }

    /// The service or client called `name`.
    pub fn service(&self, name: &str) -> Option<&ServiceInfo> {
        self.services.iter().find(|s| s.name == name)
    }

    /// The parameter called `name`.
    pub fn param(&self, name: &str) -> Option<&ParamInfo> {
        self.params.iter().find(|p| p.name == name)
    }
}

/// `Executes` as `"server"` / `"caller"` (it lives in `ferroc-ports`, which has no serde).
mod executes {
    use ferroc_ports::service::Executes;
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(e: &Executes, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(match e {
            Executes::Server => "server",
            Executes::Caller => "caller",
        })
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Executes, D::Error> {
        match String::deserialize(d)?.as_str() {
            "server" => Ok(Executes::Server),
            "caller" => Ok(Executes::Caller),
            other => Err(serde::de::Error::unknown_variant(
                other,
                &["server", "caller"],
            )),
        }
    }
}
