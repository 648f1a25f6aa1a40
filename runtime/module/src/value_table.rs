//! Ports whose value type the *model* names: the value-type table and the type-erased
//! [`DynIn`] / [`DynOut`] a flexible module (`ferroc_std.Dump`, `FlexiSelect`, …) owns.
//!
//! A flexible module is compiled once but its instances declare their ports in the
//! model (`<port name="in" dir="in" type="warehouse.RobotStatus" count="3"/>`), so the
//! code cannot name the Rust type. The [`ValueTable`] maps each model type name to a
//! [`ValueType`]: plain function pointers, monomorphised per Rust type when the type is
//! registered, that create its ports through the ordinary [`PortKind`] machinery (copy
//! or pooled, exactly as an `In<T>` would be) and read, forward, convert and format its
//! values. Nothing here is new concurrency: a `DynIn` *is* an `In<T>` behind a trait
//! object, so the lock-free port core (and its loom/Miri coverage) is reused as is.
//!
//! On the cycle path there are no locks and, for copy types, no allocations: a call is
//! one virtual call plus, for forwarding, one `TypeId` comparison. Formatting writes
//! into a caller-owned `String` that keeps its capacity; forwarding a pooled value
//! `clone_from`s into a recycled buffer (allocation-free for `Vec`/`String`, and for
//! any type whose `Clone::clone_from` reuses memory).

mod array;
mod text;
pub use array::{ArrayText, NumberArray};
#[cfg(test)]
use text::quote_tail;
pub use text::{DebugText, Number, NumberText, PlainText, ValueText};

use super::codec::Codec;
use super::value::{In, Out, PortKind, PortValue};
use super::Timestamp;
use ferroc_ports::port::{InputHandle, OutputHandle, QueueConfig};
use std::any::Any;
use std::borrow::Borrow;
use std::collections::BTreeMap;
use std::fmt::Debug;
use std::marker::PhantomData;

/// What the runtime knows about one registered value type (the table's entry).
#[derive(Clone, Copy)]
pub struct ValueType {
    rust: &'static str,
    number: bool,
    elements: bool,
    copy: bool,
    input: fn(&str, Option<QueueConfig>) -> (DynIn, InputHandle),
    output: fn(&str) -> (DynOut, OutputHandle),
    codec: Option<Codec>,
}

impl ValueType {
    /// The Rust type behind it (for messages).
    pub fn rust(&self) -> &'static str {
        self.rust
    }
    /// Whether values convert to and from `f64` (the built-in numbers).
    pub fn is_number(&self) -> bool {
        self.number
    }
    /// Whether values are numbers or arrays of numbers (element-wise access).
    pub fn has_elements(&self) -> bool {
        self.elements
    }
    /// Whether its ports take the seqlock copy path (else the pooled path).
    pub fn is_copy(&self) -> bool {
        self.copy
    }
    /// How its values cross between parts; `None` for a type registered without serde.
    pub fn codec(&self) -> Option<&Codec> {
        self.codec.as_ref()
    }
    /// The former name of [`codec`](Self::codec), kept for the crates that call it.
    pub fn wire(&self) -> Option<&Codec> {
        self.codec()
    }
}

impl std::fmt::Debug for ValueType {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "ValueType({})", self.rust)
    }
}

/// Model type name → [`ValueType`]; the built-in types are always there.
#[derive(Clone, Debug)]
pub struct ValueTable {
    types: BTreeMap<String, ValueType>,
}

impl Default for ValueTable {
    fn default() -> Self {
        let mut t = ValueTable {
            types: BTreeMap::new(),
        };
        macro_rules! numbers {
            ($($ty:ty),*) => {$(
                t.insert_serde::<$ty, NumberText>();
                t.insert_serde::<Vec<$ty>, ArrayText>();
            )*};
        }
        numbers!(f64, f32, i8, i16, i32, i64, u8, u16, u32, u64);
        t.insert_serde::<bool, PlainText>();
        t.insert_serde::<String, PlainText>();
        t.insert_serde::<Timestamp, PlainText>();
        t.insert_serde::<[f64; 2], ArrayText>();
        t.insert_serde::<[f64; 3], ArrayText>();
        t.insert_serde::<[f64; 4], ArrayText>();
        // A 4×4 matrix (a homogeneous transform), the shape robot code passes around.
        t.insert_serde::<[[f64; 4]; 4], ArrayText>();
        // Small integer arrays (encoder counts, millimetre positions from a Filter).
        t.insert_serde::<[i32; 2], ArrayText>();
        t.insert_serde::<[i32; 3], ArrayText>();
        t.insert_serde::<[i32; 4], ArrayText>();
        t.insert_serde::<std::time::Duration, PlainText>();
        // The iB2C meta signals travel as `f64` under their own model names.
        for meta in ["Stimulation", "Inhibition", "Activity", "TargetRating"] {
            t.insert_as::<f64, NumberText>(meta, Some(Codec::of::<f64>()));
        }
        t
    }
}

impl ValueTable {
    /// Registers `T` under its model name, read and written through `S`; a later
    /// registration of the same name replaces the earlier one.
    pub fn insert<T, S>(&mut self) -> &mut Self
    where
        T: PortValue + Clone,
        S: ValueText<T>,
    {
        self.insert_as::<T, S>(&T::model_type(), None)
    }

    /// Registers `T` like [`insert`](Self::insert), able to cross between parts.
    pub fn insert_serde<T, S>(&mut self) -> &mut Self
    where
        T: PortValue + Clone + serde::Serialize + serde::de::DeserializeOwned,
        S: ValueText<T>,
    {
        self.insert_as::<T, S>(&T::model_type(), Some(Codec::of::<T>()))
    }

    /// Registers `T` like [`insert_serde`](Self::insert_serde), its ROS 2 ends written
    /// and read as the message its library maps it to ([`crate::Ros2Message`]).
    pub fn insert_ros2<T, S>(&mut self) -> &mut Self
    where
        T: crate::Ros2Message + Clone,
        S: ValueText<T>,
    {
        self.insert_as::<T, S>(&T::model_type(), Some(Codec::of_ros2::<T>()))
    }

    /// Registers `T` under another model name than its own (the meta types, which are
    /// `f64` values with their own names).
    fn insert_as<T, S>(&mut self, model_type: &str, codec: Option<Codec>) -> &mut Self
    where
        T: PortValue + Clone,
        S: ValueText<T>,
    {
        let copy = std::any::TypeId::of::<T::Kind>() == std::any::TypeId::of::<super::CopyKind>();
        self.types.insert(
            model_type.to_owned(),
            ValueType {
                rust: std::any::type_name::<T>(),
                number: S::from_f64(0.0).is_some(),
                elements: S::ELEMENTS,
                copy,
                input: new_input::<T, S>,
                output: new_output::<T, S>,
                codec,
            },
        );
        self
    }

    /// The entry of a model type name (`f64`, `warehouse.RobotStatus`).
    pub fn get(&self, model_type: &str) -> Option<&ValueType> {
        self.types.get(model_type)
    }

    /// Registered model type names, sorted.
    pub fn names(&self) -> impl Iterator<Item = &str> + '_ {
        self.types.keys().map(String::as_str)
    }
}

impl ValueType {
    /// A new input port named `name` (a queue if `queue` is given) and its handle for
    /// wiring (modules get theirs from [`Setup`](super::Setup); tools and tests that
    /// observe a port of any type make one here).
    pub fn input(&self, name: &str, queue: Option<QueueConfig>) -> (DynIn, InputHandle) {
        (self.input)(name, queue)
    }
    /// A new output port named `name` and its handle for wiring.
    pub fn output(&self, name: &str) -> (DynOut, OutputHandle) {
        (self.output)(name)
    }
}

/// The typed port behind a [`DynIn`].
trait ErasedIn: Send + Sync + 'static {
    fn changed(&self) -> bool;
    fn human(&self, out: &mut String);
    fn json(&self, out: &mut String);
    fn to_f64(&self) -> Option<f64>;
    fn elements(&self, out: &mut Vec<f64>) -> bool;
    /// The `In<T>` inside.
    fn port_any(&self) -> &dyn Any;
}

/// The typed port behind a [`DynOut`].
trait ErasedOut: Send + Sync + 'static {
    fn publish_f64(&self, x: f64) -> bool;
    fn forward(&self, from: &dyn ErasedIn) -> bool;
    fn publish_elements(&self, xs: &[f64]) -> Result<(), String>;
    /// The `Out<T>` inside.
    fn port_any(&self) -> &dyn Any;
}

struct TypedIn<T: PortValue, S> {
    port: In<T>,
    _text: PhantomData<fn() -> S>,
}

struct TypedOut<T: PortValue, S> {
    port: Out<T>,
    _text: PhantomData<fn() -> S>,
}

impl<T: PortValue + Clone, S: ValueText<T>> ErasedIn for TypedIn<T, S> {
    fn changed(&self) -> bool {
        self.port.changed()
    }
    fn human(&self, out: &mut String) {
        S::human(self.port.get().borrow(), out)
    }
    fn json(&self, out: &mut String) {
        S::json(self.port.get().borrow(), out)
    }
    fn to_f64(&self) -> Option<f64> {
        S::to_f64(self.port.get().borrow())
    }
    fn elements(&self, out: &mut Vec<f64>) -> bool {
        if S::ELEMENTS {
            S::elements(self.port.get().borrow(), out);
        }
        S::ELEMENTS
    }
    fn port_any(&self) -> &dyn Any {
        &self.port
    }
}

impl<T: PortValue + Clone, S: ValueText<T>> ErasedOut for TypedOut<T, S> {
    fn publish_f64(&self, x: f64) -> bool {
        match S::from_f64(x) {
            Some(v) => {
                self.port.publish(v);
                true
            }
            None => false,
        }
    }
    fn publish_elements(&self, xs: &[f64]) -> Result<(), String> {
        if !S::ELEMENTS {
            return Err(format!(
                "`{}` is not a number or an array of numbers",
                T::model_type()
            ));
        }
        if let Some(n) = S::FIXED_LEN.filter(|n| *n != xs.len()) {
            return Err(format!(
                "`{}` has {n} element(s), not {}",
                T::model_type(),
                xs.len()
            ));
        }
        self.port.publish_with(|buffer| S::set_elements(xs, buffer));
        Ok(())
    }
    fn forward(&self, from: &dyn ErasedIn) -> bool {
        // The Rust type decides (whatever text style either side was registered with).
        let Some(from) = from.port_any().downcast_ref::<In<T>>() else {
            return false;
        };
        let value = from.get();
        self.port
            .publish_with(|buffer| buffer.clone_from(value.borrow()));
        true
    }
    fn port_any(&self) -> &dyn Any {
        &self.port
    }
}

fn new_input<T: PortValue + Clone, S: ValueText<T>>(
    name: &str,
    queue: Option<QueueConfig>,
) -> (DynIn, InputHandle) {
    let (port, handle) = <T::Kind as PortKind<T>>::input(name, queue);
    let port = TypedIn::<T, S> {
        port: In::from_port(port, handle.source()),
        _text: PhantomData,
    };
    (
        DynIn {
            name: name.to_owned(),
            port: Box::new(port),
        },
        handle,
    )
}

fn new_output<T: PortValue + Clone, S: ValueText<T>>(name: &str) -> (DynOut, OutputHandle) {
    let (port, handle) = <T::Kind as PortKind<T>>::output(name);
    let port = TypedOut::<T, S> {
        port: Out::from_port(port),
        _text: PhantomData,
    };
    (
        DynOut {
            name: name.to_owned(),
            port: Some(Box::new(port)),
        },
        handle,
    )
}

/// An input port whose value type the model chose (see the [module docs](self)).
pub struct DynIn {
    name: String,
    port: Box<dyn ErasedIn>,
}

impl DynIn {
    /// The port's name (`in/2`).
    pub fn name(&self) -> &str {
        &self.name
    }
    /// True if a value arrived since the last call ("input changed").
    #[inline]
    pub fn changed(&self) -> bool {
        self.port.changed()
    }
    /// Appends the latest value, written for people.
    pub fn write_human(&self, out: &mut String) {
        self.port.human(out)
    }
    /// Appends the latest value as one JSON value.
    pub fn write_json(&self, out: &mut String) {
        self.port.json(out)
    }
    /// The latest value as a number; `None` if the type is not a built-in number.
    #[inline]
    pub fn get_f64(&self) -> Option<f64> {
        self.port.to_f64()
    }
    /// Appends the latest value's elements as `f64` (a number is one element, arrays
    /// row by row); false (nothing appended) if the type is not numbers.
    #[inline]
    pub fn get_elements(&self, out: &mut Vec<f64>) -> bool {
        self.port.elements(out)
    }
    /// The typed port, if the model's type is `T` (a module that knows its type after
    /// all, e.g. to read a library struct's fields).
    pub fn typed<T: PortValue>(&self) -> Option<&In<T>> {
        self.port.port_any().downcast_ref::<In<T>>()
    }
}

/// An output port whose value type the model chose. Created unbound (publishing does
/// nothing) when the type is unknown: while the registry learns a type's interface,
/// or when creation has already failed with an error.
pub struct DynOut {
    name: String,
    port: Option<Box<dyn ErasedOut>>,
}

impl DynOut {
    pub(crate) fn unbound(name: &str) -> Self {
        DynOut {
            name: name.to_owned(),
            port: None,
        }
    }
    /// The port's name.
    pub fn name(&self) -> &str {
        &self.name
    }
    /// Publishes `x` converted to the port's number type (`as` semantics: saturating,
    /// NaN → 0 for integers). False if the type is not a number or the port unbound.
    #[inline]
    pub fn publish_f64(&self, x: f64) -> bool {
        self.port.as_ref().is_some_and(|p| p.publish_f64(x))
    }
    /// Publishes the latest value of `from`, which must carry the same value type.
    /// False (nothing published) if the types differ or the port is unbound.
    #[inline]
    pub fn forward(&self, from: &DynIn) -> bool {
        self.port.as_ref().is_some_and(|p| p.forward(&*from.port))
    }
    /// Publishes `xs` as the elements of a value of the port's type (saturating `as`
    /// conversions). An error, nothing published, if the type is not numbers, the
    /// port is unbound, or a fixed array has another length.
    pub fn publish_elements(&self, xs: &[f64]) -> Result<(), String> {
        match &self.port {
            Some(p) => p.publish_elements(xs),
            None => Err(format!("`{}` is not bound", self.name)),
        }
    }
    /// Whether the port exists (its type was known at creation).
    pub fn is_bound(&self) -> bool {
        self.port.is_some()
    }
    /// The typed port, if the model's type is `T`.
    pub fn typed<T: PortValue>(&self) -> Option<&Out<T>> {
        self.port.as_ref()?.port_any().downcast_ref::<Out<T>>()
    }
}

#[cfg(test)]
mod tests;
