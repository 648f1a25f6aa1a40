//! Runtime construction: one API to build an application from module types by name.
//!
//! `ferroc run` walks a checked model and calls the [`Builder`]; a generated bundle
//! makes the same calls with the concrete types. The order of calls is: add every
//! module ([`Builder::add_module`]), connect ([`Builder::connect`]), declare each
//! thread container with its step order ([`Builder::add_thread`]), then
//! [`Builder::start`]. Every mistake is an error value naming the module path and
//! port, never a panic.

mod connect;
mod containers;
mod convert;
mod inspection;
mod links;
mod locks;
mod lockstep;
mod params_from_ports;
mod reconfigure;
mod registry;
mod ros2;
mod running;
mod services;
mod start;

pub use convert::{Conversion, Select};
pub use lockstep::Lockstep;
pub use reconfigure::{Live, Reconfiguration};
pub use registry::Registry;
pub use running::{cycles_of, ContainerStatus, RunningApp};
pub use start::StartOptions;

use ferroc_exec::{Step, ThreadOptions};
use ferroc_module::behaviour::{ViolationLog, ViolationPolicy};
use ferroc_module::resource::{LockOrder, Resource};
use ferroc_module::{Determinism, Interface, Kind, Module, ParamHandle, PortGroup, Setup, Value};
use ferroc_ports::port::{InputHandle, OutputHandle, QueueConfig};
use std::collections::HashMap;
use std::sync::Arc;
use std::time::Duration;

/// Which method of a module a step calls.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum StepKind {
    /// `update` of a plain module.
    Update,
    /// `sense` of a sense-control module.
    Sense,
    /// `control` of a sense-control module.
    Control,
}

/// A module instance to create.
#[derive(Clone, Copy, Debug)]
pub struct ModuleSpec<'a> {
    /// Its element path (`robot/control/controller`), unique in the application.
    pub path: &'a str,
    /// The registered model name of its type.
    pub type_name: &'a str,
    /// Parameter values the model gives (others take the declared default).
    pub params: &'a [(String, Value)],
    /// Inputs the model connects with a queue.
    pub queues: &'a [(String, QueueConfig)],
    /// The flexible port groups the instance declares (`<port name dir type count>`
    /// in the model); empty for module types with a fixed interface.
    pub ports: &'a [PortGroup<'a>],
    /// What an iB2C behaviour does when it violates a principle (ignored by other
    /// module kinds).
    pub violations: ViolationPolicy,
}

/// When a thread container runs its cycle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Schedule {
    /// Every `period`, at absolute deadlines.
    Periodic(Duration),
    /// Whenever an input of one of its modules receives data.
    Data,
    /// Cycles back to back, without sleeping.
    Continuous,
}

/// A thread container to create.
#[derive(Clone, Debug)]
pub struct ThreadSpec {
    /// Its element path.
    pub path: String,
    /// Periodic or data-triggered.
    pub schedule: Schedule,
    /// Priority and CPU placement.
    pub options: ThreadOptions,
    /// The steps in execution order (the compiler's schedule): module path and kind.
    pub steps: Vec<(String, StepKind)>,
}

/// Why the application cannot be built.
#[derive(Debug, Clone, PartialEq)]
pub enum BuildError {
    /// No module type of this name is registered.
    UnknownType {
        /// Module path.
        path: String,
        /// The requested type.
        type_name: String,
    },
    /// Two modules with one path.
    DuplicatePath(String),
    /// A path that names no module.
    UnknownModule(String),
    /// A module has no port of this name, or it has the wrong direction.
    UnknownPort {
        /// Module path.
        path: String,
        /// Port name.
        port: String,
        /// "input" or "output".
        wanted: &'static str,
    },
    /// Creating a module reported problems (bad parameter values, ...).
    Create {
        /// Module path.
        path: String,
        /// What went wrong, one entry per problem.
        problems: Vec<String>,
    },
    /// A connection could not be made.
    Connect(String),
    /// A resource or lock-slot problem (unknown, added or bound twice).
    Resource(String),
    /// A thread container problem (a module in two containers, a step the module's
    /// kind does not have, a thread that could not start).
    Thread(String),
}

impl std::fmt::Display for BuildError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BuildError::UnknownType { path, type_name } => write!(
                f,
                "`{path}`: the module type `{type_name}` is not registered in this binary"
            ),
            BuildError::DuplicatePath(p) => write!(f, "`{p}` is added twice"),
            BuildError::UnknownModule(p) => write!(f, "there is no module `{p}`"),
            BuildError::UnknownPort { path, port, wanted } => {
                write!(f, "`{path}` has no {wanted} port `{port}`")
            }
            BuildError::Create { path, problems } => {
                write!(f, "`{path}` could not be created: {}", problems.join("; "))
            }
            BuildError::Connect(why) | BuildError::Thread(why) | BuildError::Resource(why) => {
                f.write_str(why)
            }
        }
    }
}

impl std::error::Error for BuildError {}

/// A connection the plan marks as inside one thread container.
struct LocalClaim {
    writer: usize,
    reader: usize,
    /// `a/out → b/in`, for messages.
    name: String,
    /// Makes it local at start; `None` when it cannot be (converters between, a port
    /// kind without a local path): it stays lock-free.
    pair: Option<ferroc_ports::port::LocalPair>,
}

struct Instance {
    path: String,
    kind: Kind,
    module: Option<Box<dyn Module>>,
    interface: Interface,
    inputs: Vec<(String, InputHandle)>,
    outputs: Vec<(String, OutputHandle)>,
    /// Per output: where it finds a lender of buffers (`ferroc_module::lend`).
    lenders: Vec<(String, ferroc_module::lend::LendSlot)>,
    /// Shared: a parameter driven by a port is set by a step as well as by the app.
    params: Vec<(String, Arc<ParamHandle>)>,
    services: Vec<(String, ferroc_ports::service::ServiceHandle)>,
    clients: Vec<(String, ferroc_ports::service::ClientHandle)>,
    locks: Vec<ferroc_module::setup::SlotBinding>,
    /// Converters fed by this module's outputs, run right after its steps.
    converters: Vec<Step>,
    thread: Option<usize>,
    /// One end of a connection between parts: ports only, run by no container.
    link_end: bool,
}

/// Builds an application; see the [module documentation](self).
pub struct Builder<'r> {
    registry: &'r Registry,
    modules: Vec<Instance>,
    index: HashMap<String, usize>,
    threads: Vec<ThreadSpec>,
    /// Module connections as (writer, reader, input name): a data-triggered container
    /// must not be woken by its own modules' outputs, or it would never sleep.
    connections: Vec<(usize, usize, String)>,
    /// Connections marked as inside one thread container (`ConnectOptions::local`).
    local: Vec<LocalClaim>,
    /// Application resources by name, validated against one order graph.
    resources: HashMap<String, Arc<Resource>>,
    lock_order: Arc<LockOrder>,
    /// Where the behaviours report principle violations.
    violations: Arc<ViolationLog>,
    /// The run seed every module's random source is derived from, and the reads of
    /// the wall clock and the OS's randomness that lockstep reports.
    run: Arc<Determinism>,
    /// Routes the values of links between parts.
    hub: Arc<ferroc_link::Hub>,
    /// The receiving ends of links, by link number.
    receiving: std::collections::BTreeMap<u32, ferroc_link::Receiving>,
    /// Receiving ends that handle their frames themselves (calls, parameters), by the
    /// link number they receive on.
    direct_ends: std::collections::BTreeMap<u32, Arc<dyn ferroc_link::Receive>>,
    /// The ends of links and calls built here (those with both ends here are
    /// delivered in the process; the others cross the network).
    remote: ferroc_link::transport::PartLinks,
    /// Sending ends of links that carry one output's values unchanged to other parts
    /// ([`links::Fanout`]): a link like one of them joins it instead of encoding again.
    fanouts: Vec<links::Fanout>,
    /// Outputs handed to an inspector (`inspection.rs`), shared with a reconfigurable
    /// application (`reconfigure.rs`), by module path.
    inspected: HashMap<String, Vec<(String, Arc<OutputHandle>)>>,
    /// Outputs that may lend their modules the network's buffers ([`links::Lending`]).
    lending: links::Lending,
}

impl<'r> Builder<'r> {
    /// A builder creating modules from `registry`.
    pub fn new(registry: &'r Registry) -> Self {
        Builder {
            registry,
            modules: Vec::new(),
            index: HashMap::new(),
            threads: Vec::new(),
            connections: Vec::new(),
            local: Vec::new(),
            violations: Arc::default(),
            run: Determinism::new(0),
            resources: HashMap::new(),
            lock_order: Arc::new(LockOrder::new()),
            hub: Arc::default(),
            receiving: Default::default(),
            direct_ends: Default::default(),
            remote: Default::default(),
            fanouts: Vec::new(),
            inspected: HashMap::new(),
            lending: Default::default(),
        }
    }

    /// Sets the run seed (0 until set) from which every module's random source
    /// ([`Setup::random`]) is derived with its path. Set it before adding modules:
    /// those added before keep the seed they were created with.
    pub fn set_seed(&mut self, seed: u64) {
        debug_assert!(self.modules.is_empty(), "the seed is set after modules");
        self.run = Determinism::new(seed);
    }

    /// The run seed and the modules that read the wall clock or the OS's randomness.
    pub fn run(&self) -> &Arc<Determinism> {
        &self.run
    }

    /// Creates a module instance.
    pub fn add_module(&mut self, spec: ModuleSpec<'_>) -> Result<(), BuildError> {
        if self.index.contains_key(spec.path) {
            // Checked before the type: a path added twice is the model's mistake.
            self.registry
                .entry(spec.type_name)
                .ok_or_else(|| BuildError::UnknownType {
                    path: spec.path.into(),
                    type_name: spec.type_name.into(),
                })?;
            return Err(BuildError::DuplicatePath(spec.path.into()));
        }
        let instance = create(self.registry, &self.violations, &self.run, spec)?;
        self.index.insert(spec.path.into(), self.modules.len());
        self.modules.push(instance);
        Ok(())
    }

    fn module(&self, path: &str) -> Result<usize, BuildError> {
        self.index
            .get(path)
            .copied()
            .ok_or_else(|| BuildError::UnknownModule(path.into()))
    }

    /// The interface of a created module.
    pub fn interface(&self, path: &str) -> Result<&Interface, BuildError> {
        Ok(&self.modules[self.module(path)?].interface)
    }

    /// The handle of a module's output, to connect an observer outside the model (a
    /// status display, a test probe).
    pub fn output(&self, path: &str, port: &str) -> Result<&OutputHandle, BuildError> {
        find(
            &self.modules[self.module(path)?].outputs,
            (path, port),
            "output",
        )
    }

    /// The handle of a module's input, to feed it from outside the model.
    pub fn input(&self, path: &str, port: &str) -> Result<&InputHandle, BuildError> {
        find(
            &self.modules[self.module(path)?].inputs,
            (path, port),
            "input",
        )
    }

    /// Sets a parameter of a created module (before or after start: see
    /// [`RunningApp::set_parameter`]).
    pub fn set_parameter(&self, path: &str, name: &str, value: &Value) -> Result<(), BuildError> {
        let m = &self.modules[self.module(path)?];
        let (_, handle) =
            m.params
                .iter()
                .find(|(n, _)| n == name)
                .ok_or_else(|| BuildError::Create {
                    path: path.into(),
                    problems: vec![format!("the type has no parameter `{name}`")],
                })?;
        handle.set(value).map_err(|why| BuildError::Create {
            path: path.into(),
            problems: vec![format!("parameter `{name}`: {why}")],
        })
    }

    /// Declares a thread container and the order of its steps.
    pub fn add_thread(&mut self, spec: ThreadSpec) -> Result<(), BuildError> {
        let id = self.threads.len();
        for (path, kind) in &spec.steps {
            let m = self.module(path)?;
            let instance = &mut self.modules[m];
            let fits = match kind {
                StepKind::Update => instance.kind.has_update(),
                StepKind::Sense | StepKind::Control => instance.kind == Kind::SenseControl,
            };
            if !fits {
                return Err(BuildError::Thread(format!(
                    "`{path}` is a {} module and has no {kind:?} step",
                    instance.kind.as_str()
                )));
            }
            match instance.thread {
                Some(t) if t != id => {
                    return Err(BuildError::Thread(format!(
                        "`{path}` is executed by two thread containers: `{}` and `{}`",
                        self.threads[t].path, spec.path
                    )))
                }
                _ => instance.thread = Some(id),
            }
        }
        self.threads.push(spec);
        Ok(())
    }
}

/// A module instance made by its type's factory (also for modules added while the
/// application runs, `reconfigure.rs`).
fn create(
    registry: &Registry,
    violations: &Arc<ViolationLog>,
    run: &Arc<Determinism>,
    spec: ModuleSpec<'_>,
) -> Result<Instance, BuildError> {
    let entry = registry
        .entry(spec.type_name)
        .ok_or_else(|| BuildError::UnknownType {
            path: spec.path.into(),
            type_name: spec.type_name.into(),
        })?;
    let blank = registry::blank_interface(spec.type_name, entry);
    let mut setup = Setup::new(
        blank,
        spec.params,
        spec.queues,
        registry.values(),
        spec.ports,
    )
    .for_instance(spec.path, spec.violations, violations.clone())
    .in_run(Arc::clone(run));
    let module = (entry.factory)(&mut setup);
    let mut problems = std::mem::take(&mut setup.errors);
    for (name, _) in spec.params {
        if setup.interface.param(name).is_none() {
            problems.push(format!("the type has no parameter `{name}`"));
        }
    }
    for group in spec.ports {
        if !setup.claimed.iter().any(|g| g == group.name) {
            problems.push(format!(
                "the type has no flexible port group `{}` (the model declares one)",
                group.name
            ));
        }
    }
    if !problems.is_empty() {
        return Err(BuildError::Create {
            path: spec.path.into(),
            problems,
        });
    }
    Ok(Instance {
        path: spec.path.into(),
        kind: entry.kind,
        module: Some(module),
        interface: setup.interface,
        inputs: setup.inputs,
        outputs: setup.outputs,
        lenders: setup.lenders,
        params: setup
            .params
            .into_iter()
            .map(|(name, handle)| (name, Arc::new(handle)))
            .collect(),
        services: setup.services,
        clients: setup.clients,
        locks: setup.locks,
        converters: Vec::new(),
        thread: None,
        link_end: false,
    })
}

fn find<'a, H>(
    ports: &'a [(String, H)],
    (path, port): (&str, &str),
    wanted: &'static str,
) -> Result<&'a H, BuildError> {
    ports
        .iter()
        .find(|(n, _)| n == port)
        .map(|(_, h)| h)
        .ok_or_else(|| BuildError::UnknownPort {
            path: path.into(),
            port: port.into(),
            wanted,
        })
}

#[cfg(test)]
mod behaviour_tests;
#[cfg(test)]
mod call_link_tests;
#[cfg(test)]
mod convert_tests;
#[cfg(test)]
mod determinism_tests;
#[cfg(test)]
mod flexible_tests;
#[cfg(test)]
mod lend_tests;
#[cfg(test)]
mod link_tests;
#[cfg(test)]
mod local_tests;
#[cfg(test)]
mod lock_tests;
#[cfg(test)]
mod service_tests;
#[cfg(test)]
mod stop_tests;
#[cfg(test)]
mod tests;
