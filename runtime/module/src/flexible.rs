//! Flexible port groups in [`Setup`]: a module type declares a group (`in`, inputs,
//! same type, at least one), and receives the ports the *instance* declared for it in
//! the model (`<port name="in" dir="in" type="f64" count="3"/>` → `in/0`, `in/1`,
//! `in/2`), type-erased ([`DynIn`], [`DynOut`]) or, when the code knows the type after
//! all, typed (`In<T>`, `Out<T>`).
//!
//! ```
//! # use ferroc_module::*;
//! /// Prints how many of its inputs changed (any types).
//! struct CountChanges { inputs: Vec<DynIn> }
//! impl Module for CountChanges {
//!     fn update(&mut self) {
//!         let n = self.inputs.iter().filter(|i| i.changed()).count();
//!         println!("{n} changed");
//!     }
//! }
//! impl ModuleType for CountChanges {
//!     const NAME: &'static str = "demo.CountChanges";
//!     fn create(m: &mut Setup<'_>) -> Self {
//!         CountChanges { inputs: m.flexible_inputs("in").min_count(1).build_dyn() }
//!     }
//! }
//! ```

use super::interface::{Direction, FlexibleInfo, PortInfo, Role};
use super::setup::Setup;
use super::value::{In, Out, PortValue};
use super::value_table::{DynIn, DynOut, ValueType};

/// Ports one flexible group may have at most: a model cannot make the runtime allocate
/// without limit. The compiler reports a larger `count` (M116 at the attribute,
/// `ferroc_syntax::vocabulary::MAX_GROUP_PORTS`, held equal by a test in `ferroc-host`).
pub const MAX_GROUP_PORTS: u32 = 4096;

/// One `<port name dir type count>` of a module instance: a flexible port group as
/// the model declares it. Without `count` the group is the single port `name`; with it,
/// the ports `name/0` … `name/{count-1}`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PortGroup<'a> {
    /// The group's name (`in`).
    pub name: &'a str,
    /// Input or output.
    pub dir: Direction,
    /// The model type of every port of the group (`f64`, `warehouse.RobotStatus`).
    pub model_type: &'a str,
    /// How many numbered ports; `None`: one port named like the group.
    pub count: Option<u32>,
}

impl<'a> PortGroup<'a> {
    /// A group declaration (what `ferroc run` and generated bundles pass in
    /// `ModuleSpec::ports` (`ferroc_app::builder`)).
    pub const fn new(
        name: &'a str,
        dir: Direction,
        model_type: &'a str,
        count: Option<u32>,
    ) -> Self {
        PortGroup {
            name,
            dir,
            model_type,
            count,
        }
    }

    /// The names of the group's ports, in order.
    pub fn port_names(&self) -> Vec<String> {
        match self.count {
            Some(n) => (0..n.min(MAX_GROUP_PORTS))
                .map(|k| format!("{}/{k}", self.name))
                .collect(),
            None => vec![self.name.to_owned()],
        }
    }
}

impl<'a> Setup<'a> {
    /// Declares the flexible input group `group`; finish with
    /// [`build_dyn`](FlexibleDecl::build_dyn) or [`build`](FlexibleDecl::build).
    pub fn flexible_inputs(&mut self, group: &str) -> FlexibleDecl<'_, 'a> {
        FlexibleDecl::new(self, group, Direction::In)
    }

    /// Declares the flexible output group `group`; finish with
    /// [`build_dyn_outputs`](FlexibleDecl::build_dyn_outputs) or
    /// [`build_outputs`](FlexibleDecl::build_outputs).
    pub fn flexible_outputs(&mut self, group: &str) -> FlexibleDecl<'_, 'a> {
        FlexibleDecl::new(self, group, Direction::Out)
    }

    /// Every port group the instance declares, in model order (a module that takes
    /// whatever groups it is given, like the recorder `ferroc run --record` adds).
    pub fn port_groups(&self) -> &'a [PortGroup<'a>] {
        self.groups
    }

    /// The model type the instance gave the flexible group `group` (its first
    /// declaration); `None` while the registry learns the type's interface.
    pub fn flexible_type(&self, group: &str) -> Option<&'a str> {
        self.groups
            .iter()
            .find(|g| g.name == group)
            .map(|g| g.model_type)
    }

    /// Declares the output `name` whose type is the type of the flexible group `group`
    /// (the manifest's `type="$group"`; declare the group first). Unbound while the
    /// registry learns the interface (the interface then says `$group`).
    pub fn output_like(&mut self, name: &str, group: &str) -> DynOut {
        let mut info = PortInfo {
            name: name.to_owned(),
            dir: Direction::Out,
            role: Role::Plain,
            model_type: format!("${group}"),
            unit: None,
            required: false,
            doc: None,
        };
        let Some(model_type) = self.flexible_type(group) else {
            self.record_port(info);
            return DynOut::unbound(name);
        };
        info.model_type = model_type.to_owned();
        let out = match self.value_type(name, model_type) {
            Some(vt) => {
                let (port, handle) = vt.output(name);
                self.outputs.push((name.to_owned(), handle));
                port
            }
            None => DynOut::unbound(name),
        };
        self.record_port(info);
        out
    }

    /// What the runtime knows about a model type (whether it is a number, …); `None`
    /// if it is not registered.
    pub fn value_type_of(&self, model_type: &str) -> Option<&ValueType> {
        self.values.get(model_type)
    }

    /// Reports a problem with this instance (a hostile file path, a type the module
    /// cannot handle): the Builder refuses to create it and names the module.
    pub fn problem(&mut self, what: impl Into<String>) {
        self.errors.push(what.into());
    }

    /// The table entry of `model_type`, or an error naming the port and the type.
    fn value_type(&mut self, port: &str, model_type: &str) -> Option<ValueType> {
        let found = self.values.get(model_type).copied();
        if found.is_none() {
            self.errors.push(format!(
                "port `{port}`: the value type `{model_type}` is not registered in this binary \
                 (its library registers it with `registry.register_value::<T>()`)"
            ));
        }
        found
    }
}

/// A flexible group declaration under way.
pub struct FlexibleDecl<'s, 'a> {
    setup: &'s mut Setup<'a>,
    info: FlexibleInfo,
}

impl<'s, 'a> FlexibleDecl<'s, 'a> {
    fn new(setup: &'s mut Setup<'a>, group: &str, dir: Direction) -> Self {
        FlexibleDecl {
            setup,
            info: FlexibleInfo {
                group: group.to_owned(),
                dir,
                same_type: false,
                min_count: 0,
                max_count: None,
            },
        }
    }

    /// Every port of the group has one type (`same-type="true"`).
    pub fn same_type(mut self) -> Self {
        self.info.same_type = true;
        self
    }
    /// The instance must declare at least `n` ports (`min-count`).
    pub fn min_count(mut self, n: u32) -> Self {
        self.info.min_count = n;
        self
    }
    /// The instance may declare at most `n` ports (`max-count`).
    pub fn max_count(mut self, n: u32) -> Self {
        self.info.max_count = Some(n);
        self
    }

    /// Records the group and checks the instance's declarations of it: (port name,
    /// model type) of every port, in order.
    fn ports(self, want: Direction) -> (&'s mut Setup<'a>, Vec<(String, &'a str)>) {
        let FlexibleDecl { setup, info } = self;
        let group = info.group.clone();
        if info.dir != want {
            // A mistake in the module's code, reported like a model mistake (no panic).
            setup.errors.push(format!(
                "the flexible group `{group}` is declared as {} but built as {}",
                dir_word(info.dir),
                dir_word(want)
            ));
            return (setup, Vec::new());
        }
        if setup.interface.flexible.iter().any(|f| f.group == group) {
            setup.errors.push(format!(
                "the flexible port group `{group}` is declared twice"
            ));
        }
        let mut ports = Vec::new();
        let mut first_type: Option<&str> = None;
        let groups = setup.groups;
        for g in groups.iter().filter(|g| g.name == group) {
            if g.dir != info.dir {
                setup.errors.push(format!(
                    "port group `{group}`: the model declares it as {}, the type as {}",
                    dir_word(g.dir),
                    dir_word(info.dir)
                ));
                continue;
            }
            if g.count.is_some_and(|n| n > MAX_GROUP_PORTS) {
                setup.errors.push(format!(
                    "port group `{group}`: at most {MAX_GROUP_PORTS} ports, the model declares {}",
                    g.count.unwrap_or(0)
                ));
            }
            match first_type {
                Some(t) if info.same_type && t != g.model_type => setup.errors.push(format!(
                    "port group `{group}`: all ports must have one type; `{}` differs from `{t}`",
                    g.model_type
                )),
                Some(_) => {}
                None => first_type = Some(g.model_type),
            }
            ports.extend(g.port_names().into_iter().map(|n| (n, g.model_type)));
        }
        let n = ports.len() as u64;
        // Only an instance is held to the counts: the registry learning the type's
        // interface declares no ports at all.
        let instance = !setup.path().is_empty();
        if instance
            && (n < u64::from(info.min_count) || info.max_count.is_some_and(|m| n > u64::from(m)))
        {
            setup.errors.push(format!(
                "port group `{group}` needs between {} and {} ports, the model declares {n}",
                info.min_count,
                info.max_count
                    .map_or("any number".into(), |m| m.to_string())
            ));
        }
        setup.claimed.push(group);
        setup.interface.flexible.push(info);
        (setup, ports)
    }

    /// Creates the group's input ports, type-erased. A port whose type is not in the
    /// value table is an error (and left out).
    pub fn build_dyn(self) -> Vec<DynIn> {
        let (setup, ports) = self.ports(Direction::In);
        let mut out = Vec::with_capacity(ports.len());
        for (name, model_type) in ports {
            let Some(vt) = setup.value_type(&name, model_type) else {
                continue;
            };
            let queue = setup.queue_of(&name);
            let (port, handle) = vt.input(&name, queue);
            setup.inputs.push((name.clone(), handle));
            setup.record_port(plain_port(name, Direction::In, model_type));
            out.push(port);
        }
        out
    }

    /// Creates the group's output ports, type-erased.
    pub fn build_dyn_outputs(self) -> Vec<DynOut> {
        let (setup, ports) = self.ports(Direction::Out);
        let mut out = Vec::with_capacity(ports.len());
        for (name, model_type) in ports {
            let Some(vt) = setup.value_type(&name, model_type) else {
                continue;
            };
            let (port, handle) = vt.output(&name);
            setup.outputs.push((name.clone(), handle));
            setup.record_port(plain_port(name, Direction::Out, model_type));
            out.push(port);
        }
        out
    }

    /// Creates the group's input ports typed: the model must declare them of `T`'s
    /// model type (no value table needed).
    pub fn build<T: PortValue>(self) -> Vec<In<T>> {
        let (setup, ports) = self.ports(Direction::In);
        let own = T::model_type();
        let mut out = Vec::with_capacity(ports.len());
        for (name, model_type) in ports {
            if model_type != own {
                setup.errors.push(format!(
                    "port `{name}`: the model declares type `{model_type}`, the module takes `{own}`"
                ));
                continue;
            }
            out.push(setup.input(&name).build());
        }
        out
    }

    /// Creates the group's output ports typed (see [`build`](Self::build)).
    pub fn build_outputs<T: PortValue>(self) -> Vec<Out<T>> {
        let (setup, ports) = self.ports(Direction::Out);
        let own = T::model_type();
        let mut out = Vec::with_capacity(ports.len());
        for (name, model_type) in ports {
            if model_type != own {
                setup.errors.push(format!(
                    "port `{name}`: the model declares type `{model_type}`, the module makes `{own}`"
                ));
                continue;
            }
            out.push(setup.output(&name).build());
        }
        out
    }
}

fn plain_port(name: String, dir: Direction, model_type: &str) -> PortInfo {
    PortInfo {
        name,
        dir,
        role: Role::Plain,
        model_type: model_type.to_owned(),
        unit: None,
        required: false,
        doc: None,
    }
}

fn dir_word(dir: Direction) -> &'static str {
    match dir {
        Direction::In => "an input",
        Direction::Out => "an output",
    }
}
