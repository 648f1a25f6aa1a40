//! The registry of module types: model name → factory and interface.

use super::convert::{self, Extract};
use ferroc_module::{DebugText, ValueTable, ValueText};
use ferroc_module::{Interface, Kind, Module, ModuleType, PortValue, Setup};
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
/// library types once registered with [`Registry::register_value`]), and the accessors
/// connections use to take values apart (`<convert field|index>`).
#[derive(Clone)]
pub struct Registry {
    types: BTreeMap<&'static str, Entry>,
    /// (Rust type of the value, field name or `[]` for an index) → converter factory.
    parts: BTreeMap<(&'static str, &'static str), Extract>,
    values: ValueTable,
    /// (Rust request type, Rust response type) → how calls of them cross parts.
    calls: BTreeMap<(&'static str, &'static str), ferroc_link::calls::CallEnds>,
}

impl Default for Registry {
    fn default() -> Self {
        Self::new()
    }
}

impl Registry {
    /// A registry without module types; elements of `Vec`s of numbers can be taken
    /// (`<convert index>`) and the built-in value types used on flexible ports out of
    /// the box.
    pub fn new() -> Self {
        let mut registry = Registry {
            types: BTreeMap::new(),
            parts: BTreeMap::new(),
            values: ValueTable::default(),
            calls: BTreeMap::new(),
        };
        macro_rules! lists {
            ($($ty:ty),*) => {$(
                registry.register_index::<Vec<$ty>, $ty>(|list, i| convert::element(list, i));
            )*};
        }
        lists!(f64, f32, i8, i16, i32, i64, u8, u16, u32, u64);
        registry
    }

    /// Lets connections take `field` out of an `S` (`<convert field="linear"/>`):
    /// `registry.register_field::<Velocity2D, f64>("linear", |v| v.linear)`.
    /// A library registers every field a model may take apart, next to its module
    /// types; a connection selecting an unregistered field is refused when built.
    pub fn register_field<S: PortValue, F: PortValue>(
        &mut self,
        field: &'static str,
        get: fn(&S) -> F,
    ) -> &mut Self {
        let make = convert::extractor::<S, F>(move |value, _| get(value));
        self.parts.insert((std::any::type_name::<S>(), field), make);
        self
    }

    /// Lets connections take element `index` out of an `S` (`<convert index="2"/>`);
    /// `get` returns the default value for a missing element.
    pub fn register_index<S: PortValue, F: PortValue>(
        &mut self,
        get: fn(&S, usize) -> F,
    ) -> &mut Self {
        self.parts
            .insert((std::any::type_name::<S>(), "[]"), convert::extractor(get));
        self
    }

    /// The converter factory taking `field` (or `[]`: an element) of values of the
    /// Rust type `value_type`.
    pub(crate) fn part(&self, value_type: &str, field: &str) -> Option<&Extract> {
        self.parts
            .iter()
            .find(|((ty, f), _)| *ty == value_type && *f == field)
            .map(|(_, make)| make)
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
    /// [`Behaviour::NAME`](ferroc_module::behaviour::Behaviour::NAME).
    pub fn register_behaviour<B: ferroc_module::behaviour::Behaviour>(&mut self) -> &mut Self {
        self.register::<ferroc_module::behaviour::BehaviourModule<B>>()
    }

    /// Registers the library value type `T` (declared with
    /// [`port_value!`](ferroc_module::port_value)) for ports whose type the model names: a
    /// flexible module (`ferroc_std.Dump`, `FlexiSelect`, `Logger`) can then make, read,
    /// forward and print ports of `T`'s model type. `Debug` is how it is printed
    /// (`Dump`) and logged (`Logger`, as a JSON string); `Clone` how `FlexiSelect`
    /// forwards a pooled value (`clone_from` into a recycled buffer).
    pub fn register_value<T: PortValue + Clone + std::fmt::Debug>(&mut self) -> &mut Self {
        self.values.insert::<T, DebugText>();
        self
    }

    /// Registers the library value type `T` like [`register_value`](Self::register_value),
    /// able to cross between parts: a connection from one part to another carries it
    /// encoded (the model declares such types `serde="true"`).
    pub fn register_serde<T>(&mut self) -> &mut Self
    where
        T: PortValue + Clone + std::fmt::Debug + serde::Serialize + serde::de::DeserializeOwned,
    {
        self.values.insert_serde::<T, DebugText>();
        self
    }

    /// Registers `T` like [`register_serde`](Self::register_serde), mapped to a ROS 2
    /// message of its own ([`Ros2Message`](ferroc_module::Ros2Message): its library's
    /// manifest says `ros2="package/msg/Name"` on the `<type>`): a port of `T`
    /// published or subscribed as that message, or recorded on its topic, is written
    /// and read through `T`'s functions.
    pub fn register_ros2<T>(&mut self) -> &mut Self
    where
        T: ferroc_module::Ros2Message + Clone + std::fmt::Debug,
    {
        self.values.insert_ros2::<T, DebugText>();
        self
    }

    /// Lets calls with requests `Req` and responses `Resp` cross between parts (a
    /// client in one part calling a service in another): both are encoded like values.
    pub fn register_call<Req, Resp>(&mut self) -> &mut Self
    where
        Req: serde::Serialize + serde::de::DeserializeOwned + Send + 'static,
        Resp: serde::Serialize + serde::de::DeserializeOwned + Send + 'static,
    {
        self.calls.insert(
            (std::any::type_name::<Req>(), std::any::type_name::<Resp>()),
            ferroc_link::calls::CallEnds::of::<Req, Resp>(),
        );
        self
    }

    /// How calls of these Rust request and response types cross between parts.
    pub(crate) fn call_ends(&self, types: (&str, &str)) -> Option<ferroc_link::calls::CallEnds> {
        self.calls
            .iter()
            .find(|((req, resp), _)| *req == types.0 && *resp == types.1)
            .map(|(_, wire)| *wire)
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
        services: Vec::new(),
    }
}
