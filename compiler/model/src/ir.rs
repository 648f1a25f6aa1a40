//! The resolved application: the element tree (part → thread → group → module) and a
//! petgraph graph of ports and connections. Every node carries its source span; nodes
//! made from a group type also carry the span of the instance that created them.

use crate::library::module_type::PortType;
use crate::library::{LibraryId, LibrarySet, ModuleType, PortDecl, PortDir, PortRole};
use ferroc_diagnostics::source::Span;
use ferroc_values::types::Type;
use ferroc_values::units::Unit;
use hashbrown::{HashMap, HashSet};
use petgraph::graph::{DiGraph, NodeIndex};

mod extras;
mod query;
mod ros2;
mod tables;
pub use extras::{LinkSettings, ModuleExtras};
pub use ros2::{
    Ros2, Ros2InterfaceFile, Ros2Interfaces, Ros2Node, Ros2Service, Ros2Topic, ServiceRole,
    Spanned, TopicDirection,
};
pub use tables::{Children, NodeTable};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ElementId(pub u32);

#[derive(Debug)]
pub enum ElementKind {
    Application,
    Part {
        host: Option<(String, Span)>,
    },
    /// `period` in seconds; `None` for data-triggered containers.
    Thread {
        period: Option<f64>,
        /// `pool="n"` with n ≥ 2: n workers (not an exclusive context).
        pool: Option<u32>,
        /// `trigger="data"`.
        data_trigger: bool,
        /// `trigger="continuous"`: cycles back to back, no sleeping (benchmarks,
        /// simulations that run faster than real time).
        continuous: bool,
        /// `wait=`: how a data-triggered container waits for data.
        wait: Wait,
    },
    Group,
    Module(ModuleInstance),
}

/// `wait=` of a data-triggered thread container: how its thread waits for data.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Wait {
    /// Sleeps until woken (no CPU while idle; a thread wakeup of latency).
    #[default]
    Park,
    /// Busy-polls: the lowest latency, and a whole core (S104 counts it as 100 %).
    Spin,
    /// Polls as `Spin` does for a bounded time, then parks.
    Adaptive,
    /// No thread waits: the cycle runs in the thread that delivers the trigger value
    /// (S108 refuses steps that could block it).
    Inline,
}

impl Wait {
    /// The model's spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            Wait::Park => "park",
            Wait::Spin => "spin",
            Wait::Adaptive => "adaptive",
            Wait::Inline => "inline",
        }
    }

    /// Parses the model's spelling (the validator has rejected anything else).
    pub fn parse(text: &str) -> Option<Self> {
        match text {
            "park" => Some(Wait::Park),
            "spin" => Some(Wait::Spin),
            "adaptive" => Some(Wait::Adaptive),
            "inline" => Some(Wait::Inline),
            _ => None,
        }
    }
}

#[derive(Debug)]
pub struct ModuleInstance {
    pub library: LibraryId,
    pub type_index: usize,
    pub type_span: Span,
    /// Ports that exist only for this instance: flexible ports, `inhibition/k`, channels.
    pub extra_ports: Vec<PortDecl>,
    /// Types of the instance's flexible port groups, for `$group` port types.
    pub flexible_types: Vec<(String, Type, Option<Unit>)>,
    pub params: Vec<ParamValue>,
    /// What few instances write (`<bind>`, `characteristic`, `budget`,
    /// `ib2c-violations`), boxed: inline, these fields made every element of the tree
    /// 80 bytes larger (B1).
    pub extras: Option<Box<ModuleExtras>>,
}

/// Where a parameter's value comes from.
#[derive(Debug)]
pub enum ParamSource {
    Inline,
    /// `config="file#/a/b"`: the entry's text and span, or why it is missing.
    Config(Result<(String, Span), String>),
    /// `cmdline=` without inline text: given at start-up.
    Cmdline,
}

#[derive(Debug)]
pub struct ParamValue {
    pub name: String,
    pub name_span: Span,
    pub text: String,
    /// The text's span (or the element's, for config and command-line values).
    pub span: Span,
    pub source: ParamSource,
    pub source_span: Span,
    /// `cmdline="NAME"`: a value given at start-up under NAME overrides the others.
    pub cmdline: Option<(String, Span)>,
}

impl ParamValue {
    /// The value given on the command line for this parameter, if any.
    pub fn from_cmdline<'a>(&self, given: &'a [(String, String)]) -> Option<&'a str> {
        let (name, _) = self.cmdline.as_ref()?;
        given
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }
}

#[derive(Debug, Clone)]
pub struct GroupPort {
    pub name: String,
    pub dir: PortDir,
    pub ty: Type,
    pub unit: Option<Unit>,
    pub span: Span,
}

#[derive(Debug)]
pub struct ElementNode {
    pub kind: ElementKind,
    pub name: String,
    pub parent: Option<ElementId>,
    pub name_span: Span,
    /// The whole element in its (possibly group type) definition.
    pub span: Span,
    /// The `<group type=…>` that instantiated the definition this element comes from.
    pub instantiated_at: Option<Span>,
    pub group_ports: Vec<GroupPort>,
    /// The nearest thread container above (or the element itself for threads).
    pub thread: Option<ElementId>,
    pub part: Option<ElementId>,
}

/// One end of a connection.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Endpoint {
    Port { element: ElementId, port: u32 },
    GroupPort { element: ElementId, port: u32 },
    Param { element: ElementId, param: u32 },
}

impl Endpoint {
    pub fn element(&self) -> ElementId {
        match *self {
            Endpoint::Port { element, .. }
            | Endpoint::GroupPort { element, .. }
            | Endpoint::Param { element, .. } => element,
        }
    }
}

#[derive(Debug, Clone)]
pub struct ConvertStep {
    pub span: Span,
    /// `index="k"` with the span of its value.
    pub index: Option<(u32, Span)>,
    pub field: Option<(String, Span)>,
    pub scale: Option<(f64, Span)>,
    pub offset: Option<(f64, Span)>,
    pub to_type: Option<(Type, Span)>,
}

#[derive(Debug)]
pub struct Connection {
    pub from: Endpoint,
    pub to: Endpoint,
    /// `port[i]`: element `i` of an array or sequence port.
    pub from_index: Option<u32>,
    pub to_index: Option<u32>,
    /// The `<connect>` tag name.
    pub span: Span,
    pub from_span: Span,
    pub to_span: Span,
    pub queue: Option<u32>,
    pub on_full: Option<String>,
    pub delay: bool,
    /// `initial="k"`: items in the queue at start.
    pub initial: u32,
    /// The settings of a link between parts, when any is written (boxed: almost no
    /// connection sets one, and unboxed they were half of each of the ~200,000
    /// connections of a 100,000-module model, B1).
    pub link: Option<Box<LinkSettings>>,
    pub converts: Vec<ConvertStep>,
    pub instantiated_at: Option<Span>,
    /// The element whose `<connect>` this is (the application or a group).
    pub scope: ElementId,
}

impl Connection {
    /// The `on-full=` policy in force: the one written, else the language's default.
    pub fn on_full_policy(&self) -> &str {
        self.on_full
            .as_deref()
            .unwrap_or(ferroc_syntax::vocabulary::DEFAULT_ON_FULL)
    }

    /// Whether a writer waits for room: a queue whose policy is `block`.
    pub fn blocks_when_full(&self) -> bool {
        self.queue.is_some() && self.on_full_policy() == "block"
    }
}

/// What a check needs to know about one end of a connection.
#[derive(Debug, Clone)]
pub struct PortView<'a> {
    pub name: &'a str,
    /// The declared type; for a flexible port, the type the instance fixed.
    pub ty: &'a Type,
    pub unit: Option<&'a Unit>,
    pub span: Span,
    pub required: bool,
    pub merge: bool,
    pub role: PortRole,
    pub dir: PortDir,
}

#[derive(Debug)]
pub struct Application {
    pub name: String,
    pub span: Span,
    pub elements: Vec<ElementNode>,
    pub connections: Vec<Connection>,
    /// Ports that take part in connections, with connections as edges (weight: index).
    pub graph: DiGraph<Endpoint, usize>,
    /// The graph's node of each endpoint; see [`Application::node`].
    pub nodes: NodeTable,
    /// Named children of each element (the scope of path segments); see [`Application::child`].
    pub children: Children,
    /// `<resource>`s (named locks) of the model and its fragments.
    pub resources: Vec<Resource>,
    /// `<application profile>`: the framework whose execution semantics apply.
    pub profile: Profile,
    /// `<application ib2c-violations>`: the policy of behaviours that give none.
    pub ib2c_violations: Option<String>,
    /// `<application seed>`: the run seed when the command line gives none, so that a
    /// model's runs repeat as printed (`--seed` overrides it).
    pub seed: Option<u64>,
    /// What the timing checks (S102–S107) read: priorities, cores, flows.
    pub timing: Timing,
    /// Ends of `<connect>`s whose other end did not resolve (reported there): checks that
    /// a port is connected count these as connected, one root cause being one finding.
    pub cut_off: HashSet<Endpoint>,
    /// `<ros2>` nodes of parts and `<ros2-external>` nodes (docs/ros2.md).
    pub ros2: Ros2,
    /// `<part shared-memory…>` settings of the parts that give any (docs/zenoh.md).
    pub shared_memory: HashMap<ElementId, SharedMemory>,
}

/// A part's shared-memory settings for its links to parts on the same computer
/// (`<part shared-memory="off" shared-memory-threshold="16 KiB"
/// shared-memory-pool="128 MiB">`, docs/zenoh.md "Shared memory"). `None` keeps
/// ferroc's default; a `--zenoh-config` file that sets the same Zenoh key wins.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SharedMemory {
    /// `shared-memory="on|off"`.
    pub enabled: Option<bool>,
    /// `shared-memory-threshold`: values of at least this many encoded bytes go
    /// through the pool.
    pub threshold: Option<u64>,
    /// `shared-memory-pool`: the pool's size in bytes.
    pub pool: Option<u64>,
}

impl SharedMemory {
    /// ferroc's threshold when the model gives none (`ferroc_zenoh::shm::THRESHOLD`).
    pub const DEFAULT_THRESHOLD: u64 = 4096;
    /// ferroc's pool when the model gives none (`ferroc_zenoh::shm::POOL_SIZE`).
    pub const DEFAULT_POOL: u64 = 64 << 20;
    /// The smallest pool the model accepts: smaller holds no value worth sharing.
    pub const MIN_POOL: u64 = 64 << 10;
    /// The largest pool the model accepts: more is a mistake of unit (`64 GiB` for
    /// `64 MiB`), and more than `/dev/shm` of most computers holds.
    pub const MAX_POOL: u64 = 4 << 30;
}

/// Timing attributes of the model, keyed by element (most models declare few of them).
#[derive(Debug, Default)]
pub struct Timing {
    /// `<thread priority>` (higher runs first) with the value's span.
    pub priority: HashMap<ElementId, (u32, Span)>,
    /// `<thread cpu>`: the core a container is pinned to, with the value's span.
    pub cpu: HashMap<ElementId, (u32, Span)>,
    /// `<part cores>`: cores of the part's host, with the value's span.
    pub cores: HashMap<ElementId, (u32, Span)>,
    /// `<application utilisation-warning="80%">` as a fraction, with the value's span.
    pub warning: Option<(f64, Span)>,
    /// `<flow>` requirements whose ends resolve.
    pub flows: Vec<Flow>,
}

/// `<flow name from to max-latency>`, ends resolved to modules.
#[derive(Debug, Clone)]
pub struct Flow {
    pub name: String,
    /// The `<flow>` tag.
    pub span: Span,
    pub from: ElementId,
    pub from_span: Span,
    pub to: ElementId,
    pub to_span: Span,
    /// Seconds, with the value's span.
    pub max_latency: (f64, Span),
}

impl Application {
    /// The budget of one activation of a module: the instance's, else its type's.
    pub fn budget(&self, libs: &LibrarySet, id: ElementId) -> Option<(f64, Span)> {
        match &self.element(id).kind {
            ElementKind::Module(m) => m
                .budget()
                .or(libs.get(m.library).module_types[m.type_index].budget),
            _ => None,
        }
    }

    /// The host a part runs on: its `host` label, else the part itself.
    pub fn host_of(&self, part: ElementId) -> HostKey<'_> {
        match &self.element(part).kind {
            ElementKind::Part { host: Some((h, _)) } => HostKey::Label(h),
            _ => HostKey::Part(part),
        }
    }
}

/// Which host a part runs on (see [`Application::host_of`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum HostKey<'a> {
    Label(&'a str),
    Part(ElementId),
}

/// A `<resource>`: a named lock.
#[derive(Debug, Clone)]
pub struct Resource {
    pub name: String,
    pub span: Span,
    pub level: Option<u32>,
    pub recursive: bool,
}

/// Execution semantics that change deadlock verdicts (`reference/deadlocks.md` §2.10).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Profile {
    /// Services run in the server's thread container; the response wakes the caller.
    #[default]
    Generic,
    /// FINROC: a call to a server in the same part runs inline in the caller's thread; an
    /// unconnected call fails at once.
    Finroc,
}
