//! [`Setup`]: what a module type's `create` uses to declare and create its ports and
//! parameters in one go.
//!
//! ```
//! # use ferroc_module::*;
//! struct Scale { input: In<f64>, output: Out<f64>, factor: Parameter<f64> }
//! impl Module for Scale {
//!     fn update(&mut self) {
//!         let factor = self.factor.get();
//!         self.output.publish(self.input.get() * factor);
//!     }
//! }
//! impl ModuleType for Scale {
//!     const NAME: &'static str = "demo.Scale";
//!     fn create(m: &mut Setup<'_>) -> Self {
//!         Scale {
//!             input: m.input("input").required().build(),
//!             output: m.output("output").build(),
//!             factor: m.param("factor").default(1.0).build(),
//!         }
//!     }
//! }
//! ```

use super::flexible::PortGroup;
use super::interface::{Direction, Interface, MetaType, ParamInfo, PortInfo, Role};
use super::param::{Check, ParamHandle, ParamValue, Parameter, Value};
use super::value::{In, Out, PortKind, PortValue};
use super::value_table::ValueTable;
use crate::behaviour::{ViolationLog, ViolationPolicy};
use crate::determinism::{Determinism, Nondeterminism, WallClock};
use crate::random::{seed_from_os, Random};
use crate::resource::LockSlot;
use ferroc_ports::port::{CopyPeek, InputHandle, OutputHandle, QueueConfig};
use std::any::Any;
use std::sync::{Arc, OnceLock};

/// The creation context of one module instance (or of the registry describing a type,
/// where nothing is given and every declaration falls back to its default).
pub struct Setup<'a> {
    given: &'a [(String, Value)],
    queues: &'a [(String, QueueConfig)],
    /// Value types by model name, for ports the instance declares.
    pub(crate) values: &'a ValueTable,
    /// The flexible port groups the instance declares (`<port name dir type count>`).
    pub(crate) groups: &'a [PortGroup<'a>],
    /// Flexible groups the type declared (the Builder refuses an instance declaring
    /// any other).
    #[doc(hidden)]
    pub claimed: Vec<String>,
    path: String,
    /// The run seed and where reads of the wall clock and the OS's randomness go.
    run: Arc<Determinism>,
    /// Streams handed out by [`Setup::random`] so far.
    streams: u64,
    pub(crate) policy: ViolationPolicy,
    pub(crate) log: Arc<ViolationLog>,
    #[doc(hidden)]
    pub interface: Interface,
    #[doc(hidden)]
    pub inputs: Vec<(String, InputHandle)>,
    #[doc(hidden)]
    pub outputs: Vec<(String, OutputHandle)>,
    /// Per output: where it finds a lender of buffers ([`crate::lend`]).
    #[doc(hidden)]
    pub lenders: Vec<(String, crate::lend::LendSlot)>,
    #[doc(hidden)]
    pub params: Vec<(String, ParamHandle)>,
    /// Services and clients, for the Builder to connect (see `services.rs`).
    #[doc(hidden)]
    pub services: Vec<(String, ferroc_ports::service::ServiceHandle)>,
    #[doc(hidden)]
    pub clients: Vec<(String, ferroc_ports::service::ClientHandle)>,
    /// Lock slots, bound to resources by the Builder.
    #[doc(hidden)]
    pub locks: Vec<SlotBinding>,
    #[doc(hidden)]
    pub errors: Vec<String>,
    /// Readers of the activity-typed inputs declared so far (the behaviour base
    /// watches them for the goal-state principle).
    pub(crate) activity_inputs: Vec<CopyPeek<f64>>,
}

/// The Builder's end of a [`LockSlot`]: where to put the module path and the resource.
#[doc(hidden)]
pub struct SlotBinding {
    #[doc(hidden)]
    pub slot: String,
    #[doc(hidden)]
    pub module: Arc<OnceLock<String>>,
    #[doc(hidden)]
    pub resource: Arc<OnceLock<Arc<crate::resource::Resource>>>,
}

impl<'a> Setup<'a> {
    #[doc(hidden)]
    pub fn new(
        interface: Interface,
        given: &'a [(String, Value)],
        queues: &'a [(String, QueueConfig)],
        values: &'a ValueTable,
        groups: &'a [PortGroup<'a>],
    ) -> Self {
        Setup {
            given,
            queues,
            values,
            groups,
            claimed: Vec::new(),
            path: String::new(),
            run: Determinism::new(0),
            streams: 0,
            policy: ViolationPolicy::default(),
            log: Arc::default(),
            interface,
            inputs: Vec::new(),
            outputs: Vec::new(),
            lenders: Vec::new(),
            params: Vec::new(),
            services: Vec::new(),
            clients: Vec::new(),
            locks: Vec::new(),
            errors: Vec::new(),
            activity_inputs: Vec::new(),
        }
    }

    /// Declares a lock slot (the manifest's `<locks order="…">` names them); the model
    /// binds it to an application resource. Take it with [`LockSlot::lock`].
    pub fn lock(&mut self, slot: &str) -> LockSlot {
        if self.locks.iter().any(|l| l.slot == slot) {
            self.errors
                .push(format!("the lock slot `{slot}` is declared twice"));
        }
        let binding = SlotBinding {
            slot: slot.to_owned(),
            module: Arc::new(OnceLock::new()),
            resource: Arc::new(OnceLock::new()),
        };
        let handle = LockSlot {
            slot: slot.to_owned(),
            module: Arc::clone(&binding.module),
            resource: Arc::clone(&binding.resource),
        };
        self.locks.push(binding);
        handle
    }

    /// The instance being created: its path, its iB2C violation policy and where its
    /// violations are reported.
    #[doc(hidden)]
    pub fn for_instance(
        mut self,
        path: &str,
        policy: ViolationPolicy,
        log: Arc<ViolationLog>,
    ) -> Self {
        self.path = path.to_owned();
        self.policy = policy;
        self.log = log;
        self
    }

    /// The run the instance belongs to: its seed, and where reads of the wall clock
    /// and of the OS's randomness are reported.
    #[doc(hidden)]
    pub fn in_run(mut self, run: Arc<Determinism>) -> Self {
        self.run = run;
        self
    }

    /// The module's random source: a stream derived from the run seed (`--seed`) and
    /// the module's path, the same on every run with that seed. Each call gives
    /// another independent stream (the first call's is always the same one).
    pub fn random(&mut self) -> Random {
        let stream = self.streams;
        self.streams += 1;
        Random::for_module(self.run.seed(), &self.path, stream)
    }

    /// A random source seeded from the operating system's randomness: different on
    /// every run whatever the seed. In lockstep the runtime reports the module (once)
    /// as making the run differ; prefer [`Setup::random`].
    pub fn os_random(&mut self) -> Random {
        self.run.note(&self.path, Nondeterminism::OsRandom);
        Random::from_seed(seed_from_os())
    }

    /// The wall clock, for what must be real time even in lockstep; reading it in
    /// lockstep is reported (once). For the time of a cycle take `Timestamp::now()`,
    /// which is model time in lockstep.
    pub fn wall_clock(&self) -> WallClock {
        WallClock::new(&self.path, Arc::clone(&self.run))
    }

    /// The element path of the module being created (`robot/control/avoid`); empty
    /// while the registry only learns the type's interface.
    pub fn path(&self) -> &str {
        &self.path
    }

    /// Declares an iB2C meta input (an `f64` in [0, 1]) with the given meta type. The
    /// behaviour base declares `stimulation` and `inhibition/k` itself; fusions use it
    /// for their channels' `in/k/activity` and `in/k/target_rating`. Inputs of type
    /// `Activity` are activity inputs for the goal-state principle.
    pub fn meta_input(&mut self, name: &str, ty: MetaType) -> In<f64> {
        InputDecl(self.port_decl(name, Direction::In, Role::Meta))
            .meta(ty)
            .build()
    }

    /// Declares an iB2C meta output (an `f64` in [0, 1]) with the given meta type.
    pub fn meta_output(&mut self, name: &str, ty: MetaType) -> Out<f64> {
        OutputDecl(self.port_decl(name, Direction::Out, Role::Meta))
            .meta(ty)
            .build()
    }

    fn port_decl(&mut self, name: &str, dir: Direction, role: Role) -> PortDecl<'_, 'a> {
        PortDecl {
            meta: None,
            setup: self,
            info: PortInfo {
                name: name.to_owned(),
                dir,
                role,
                model_type: String::new(),
                unit: None,
                required: false,
                doc: None,
            },
        }
    }

    /// Declares an input of a plain module.
    pub fn input(&mut self, name: &str) -> InputDecl<'_, 'a> {
        InputDecl(self.port_decl(name, Direction::In, Role::Plain))
    }
    /// Declares an output of a plain module.
    pub fn output(&mut self, name: &str) -> OutputDecl<'_, 'a> {
        OutputDecl(self.port_decl(name, Direction::Out, Role::Plain))
    }
    /// Declares a sensor input (read by the `sense` step).
    pub fn sensor_input(&mut self, name: &str) -> InputDecl<'_, 'a> {
        InputDecl(self.port_decl(name, Direction::In, Role::Sensor))
    }
    /// Declares a sensor output (written by the `sense` step).
    pub fn sensor_output(&mut self, name: &str) -> OutputDecl<'_, 'a> {
        OutputDecl(self.port_decl(name, Direction::Out, Role::Sensor))
    }
    /// Declares a controller input (read by the `control` step).
    pub fn controller_input(&mut self, name: &str) -> InputDecl<'_, 'a> {
        InputDecl(self.port_decl(name, Direction::In, Role::Controller))
    }
    /// Declares a controller output (written by the `control` step).
    pub fn controller_output(&mut self, name: &str) -> OutputDecl<'_, 'a> {
        OutputDecl(self.port_decl(name, Direction::Out, Role::Controller))
    }

    /// Declares a parameter; finish with [`ParamDecl::build`].
    pub fn param<T: ParamValue + Default>(&mut self, name: &str) -> ParamDecl<'_, 'a, T> {
        ParamDecl {
            setup: self,
            info: ParamInfo {
                name: name.to_owned(),
                model_type: T::model_type().to_owned(),
                unit: None,
                min: None,
                max: None,
                default: None,
                choices: Vec::new(),
                doc: None,
            },
            default: None,
            meta: false,
        }
    }

    /// The queue the model's connection gives input `name`, if any.
    pub(crate) fn queue_of(&self, name: &str) -> Option<QueueConfig> {
        self.queues.iter().find(|(n, _)| n == name).map(|(_, q)| *q)
    }

    pub(crate) fn record_port(&mut self, info: PortInfo) {
        self.refuse_taken_name(&info.name);
        self.interface.ports.push(info);
    }

    /// Ports, services and clients share one namespace per module.
    pub(crate) fn refuse_taken_name(&mut self, name: &str) {
        if self.interface.port(name).is_some() || self.interface.service(name).is_some() {
            self.errors
                .push(format!("the port `{name}` is declared twice"));
        }
    }
}

/// A port declaration under way (shared by inputs and outputs).
pub struct PortDecl<'s, 'a> {
    setup: &'s mut Setup<'a>,
    info: PortInfo,
    meta: Option<MetaType>,
}

impl PortDecl<'_, '_> {
    /// The model type of a port carrying `T`: `T`'s own, or the meta type the
    /// declaration names (then `T` must be `f64`, which meta signals travel as).
    fn model_type<T: PortValue>(&mut self) -> String {
        let own = T::model_type();
        match self.meta {
            Some(meta) if own == "f64" => meta.as_str().to_owned(),
            Some(meta) => {
                self.setup.errors.push(format!(
                    "port `{}`: a `{}` port carries `f64`, not `{own}`",
                    self.info.name,
                    meta.as_str()
                ));
                own
            }
            None => own,
        }
    }
}

/// An input declaration; finish with [`build`](InputDecl::build).
pub struct InputDecl<'s, 'a>(PortDecl<'s, 'a>);
/// An output declaration; finish with [`build`](OutputDecl::build).
pub struct OutputDecl<'s, 'a>(PortDecl<'s, 'a>);

macro_rules! port_decl_setters {
    ($decl:ident) => {
        impl<'s, 'a> $decl<'s, 'a> {
            /// The unit of the values (`m/s`); connections to ports of another unit of
            /// the same dimension are scaled automatically.
            pub fn unit(mut self, unit: &str) -> Self {
                self.0.info.unit = Some(unit.to_owned());
                self
            }
            /// A one-line description (shown in manifests and tools).
            pub fn doc(mut self, doc: &str) -> Self {
                self.0.info.doc = Some(doc.to_owned());
                self
            }
            /// The port carries an iB2C meta signal of this type (`Activity`, …): the
            /// value type must be `f64`, the model type is the meta type.
            pub fn meta(mut self, ty: MetaType) -> Self {
                self.0.meta = Some(ty);
                self
            }
        }
    };
}
port_decl_setters!(InputDecl);
port_decl_setters!(OutputDecl);

impl<'s, 'a> InputDecl<'s, 'a> {
    /// The input must be connected (the checker reports it otherwise).
    pub fn required(mut self) -> Self {
        self.0.info.required = true;
        self
    }

    /// Creates the port. If the model connects it with `queue=N`, it is a queue.
    pub fn build<T: PortValue>(mut self) -> In<T> {
        let model_type = self.0.model_type::<T>();
        let PortDecl {
            setup,
            mut info,
            meta,
        } = self.0;
        info.model_type = model_type;
        let queue = setup.queue_of(&info.name);
        let (port, handle) = T::Kind::input(&info.name, queue);
        if meta == Some(MetaType::Activity) {
            // Only `f64` ports get here without an error (see `model_type`).
            if let Some(port) =
                (&port as &dyn Any).downcast_ref::<ferroc_ports::port::CopyInputPort<f64>>()
            {
                setup.activity_inputs.push(port.peek());
            }
        }
        let source = handle.source();
        setup.inputs.push((info.name.clone(), handle));
        setup.record_port(info);
        In::from_port(port, source)
    }
}

impl<'s, 'a> OutputDecl<'s, 'a> {
    /// Creates the port.
    pub fn build<T: PortValue>(mut self) -> Out<T> {
        let model_type = self.0.model_type::<T>();
        let PortDecl {
            setup, mut info, ..
        } = self.0;
        info.model_type = model_type;
        let (port, handle) = T::Kind::output(&info.name);
        setup.outputs.push((info.name.clone(), handle));
        let lend = crate::lend::LendSlot::default();
        setup.lenders.push((info.name.clone(), lend.clone()));
        setup.record_port(info);
        Out::from_port(port).with_lend(lend)
    }
}

/// A parameter declaration under way; finish with [`build`](ParamDecl::build).
pub struct ParamDecl<'s, 'a, T> {
    setup: &'s mut Setup<'a>,
    info: ParamInfo,
    default: Option<T>,
    /// A meta signal: values outside [0, 1] are refused (without a declared range).
    meta: bool,
}

impl ParamDecl<'_, '_, f64> {
    /// The parameter is an iB2C meta signal (`type="Activity"` in the manifest): its
    /// model type is the meta type and every value must lie in [0, 1].
    pub fn meta(mut self, ty: MetaType) -> Self {
        self.info.model_type = ty.as_str().to_owned();
        self.meta = true;
        self
    }
}

impl<'s, 'a, T: ParamValue + Default> ParamDecl<'s, 'a, T> {
    /// The value used when the model gives none. Without a default the model must give
    /// one.
    pub fn default(mut self, value: T) -> Self {
        self.info.default = Some(value.to_text());
        self.default = Some(value);
        self
    }
    /// The unit the module wants its value in; models may write any unit of the same
    /// dimension and the checker converts.
    pub fn unit(mut self, unit: &str) -> Self {
        self.info.unit = Some(unit.to_owned());
        self
    }
    /// The allowed range (inclusive), enforced by the checker and on every later set.
    pub fn range(mut self, min: f64, max: f64) -> Self {
        self.info.min = Some(min);
        self.info.max = Some(max);
        self
    }
    /// The allowed values of a string parameter.
    pub fn choices(mut self, choices: &[&str]) -> Self {
        self.info.choices = choices.iter().map(|c| (*c).to_owned()).collect();
        self
    }
    /// A one-line description.
    pub fn doc(mut self, doc: &str) -> Self {
        self.info.doc = Some(doc.to_owned());
        self
    }

    /// Creates the parameter with the model's value, else the default.
    pub fn build(self) -> Parameter<T> {
        let ParamDecl {
            setup,
            info,
            default,
            meta,
        } = self;
        let check = Check {
            min: if meta { Some(0.0) } else { info.min },
            max: if meta { Some(1.0) } else { info.max },
            choices: info.choices.clone(),
        };
        let given = setup.given.iter().find(|(name, _)| *name == info.name);
        let value = match (given, default) {
            (Some((_, value)), default) => {
                match T::from_value(value).and_then(|v| check.validate(value).map(|()| v)) {
                    Ok(v) => v,
                    Err(why) => {
                        setup
                            .errors
                            .push(format!("parameter `{}`: {why}", info.name));
                        default.unwrap_or_default()
                    }
                }
            }
            (None, Some(default)) => default,
            (None, None) => {
                setup.errors.push(format!(
                    "parameter `{}` has no value and no default",
                    info.name
                ));
                T::default()
            }
        };
        if setup.interface.param(&info.name).is_some() {
            setup
                .errors
                .push(format!("the parameter `{}` is declared twice", info.name));
        }
        let (parameter, handle) = Parameter::new(&info.name, value, Some(check));
        setup.params.push((info.name.clone(), handle));
        setup.interface.params.push(info);
        parameter
    }
}
