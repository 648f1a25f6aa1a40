//! The registry of module types: model name → factory and interface.

use crate::module::{DebugText, ValueTable, ValueText};
use crate::module::{Interface, Kind, Module, ModuleType, PortValue, Setup};
use std::collections::BTreeMap;

pub(crate) type Factory = fn(&mut Setup<'_>) -> Box<dyn Module>;

#[derive(Clone, Copy)]
pub(crate) struct Entry {
    pub kind: Kind,
    pub rust: &'static str,
    pub doc: &'static str,
    pub factory: Factory,
}

fn create_boxed<M: ModuleType>(m: &mut Setup<'_>) -> Box<dyn Module> {
    Box::new(M::create(m))
}

/// Every module type a `ferroc` binary (or a bundle) can create, by model name, and
/// the value types its flexible modules can make ports of (the built-in types always;
/// library types once registered with [`Registry::register_value`]).
#[derive(Default, Clone)]
pub struct Registry {
    types: BTreeMap<&'static str, Entry>,
    values: ValueTable,
}

impl Registry {
    /// An empty registry.
    pub fn new() -> Self {
        Self::default()
    }

    /// Registers `M` under [`ModuleType::NAME`] (a later registration of the same name
    /// replaces the earlier one).
    pub fn register<M: ModuleType>(&mut self) -> &mut Self {
        self.types.insert(
            M::NAME,
            Entry {
                kind: M::KIND,
                rust: std::any::type_name::<M>(),
                doc: M::DOC,
                factory: create_boxed::<M>,
            },
        );
        self
    }

    /// Registers the iB2C behaviour `B` (wrapped in the behaviour base) under
    /// [`Behaviour::NAME`](crate::behaviour::Behaviour::NAME).
    pub fn register_behaviour<B: crate::behaviour::Behaviour>(&mut self) -> &mut Self {
        self.register::<crate::behaviour::BehaviourModule<B>>()
    }

    /// Registers the library value type `T` (declared with
    /// [`port_value!`](crate::port_value)) for ports whose type the model names: a
    /// flexible module (`ferroc_std.Dump`, `FlexiSelect`, `Logger`) can then make, read,
    /// forward and print ports of `T`'s model type. `Debug` is how it is printed
    /// (`Dump`) and logged (`Logger`, as a JSON string); `Clone` how `FlexiSelect`
    /// forwards a pooled value (`clone_from` into a recycled buffer).
    pub fn register_value<T: PortValue + Clone + std::fmt::Debug>(&mut self) -> &mut Self {
        self.values.insert::<T, DebugText>();
        self
    }

    /// Registers `T` with its own text style `S` (a [`ValueText`]): for a type that
    /// should print other than its `Debug` output, or a number-like type that `Sum`
    /// may add.
    pub fn register_value_with<T: PortValue + Clone, S: ValueText<T>>(&mut self) -> &mut Self {
        self.values.insert::<T, S>();
        self
    }

    /// The value types ports can be made of by model name.
    pub fn values(&self) -> &ValueTable {
        &self.values
    }

    /// Whether a type of this model name is registered.
    pub fn contains(&self, name: &str) -> bool {
        self.types.contains_key(name)
    }

    /// Registered model names, sorted.
    pub fn names(&self) -> impl Iterator<Item = &'static str> + '_ {
        self.types.keys().copied()
    }

    pub(crate) fn entry(&self, name: &str) -> Option<&Entry> {
        self.types.get(name)
    }

    /// The interface the type's Rust code declares (learned by creating one instance
    /// with every parameter at its default, then dropping it).
    pub fn interface(&self, name: &str) -> Option<Interface> {
        let (&name, entry) = self.types.get_key_value(name)?;
        let mut setup = Setup::new(blank_interface(name, entry), &[], &[], &self.values, &[]);
        drop((entry.factory)(&mut setup));
        Some(setup.interface)
    }
}

pub(crate) fn blank_interface(name: &str, entry: &Entry) -> Interface {
    Interface {
        name: name.to_owned(),
        rust: entry.rust.to_owned(),
        kind: entry.kind,
        doc: (!entry.doc.is_empty()).then(|| entry.doc.to_owned()),
        ports: Vec::new(),
        params: Vec::new(),
        flexible: Vec::new(),
    }
}
