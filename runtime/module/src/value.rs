//! Port value types and the typed port fields modules own: [`In<T>`] and [`Out<T>`].
//!
//! Every Rust type that travels through ports names its model type (`f64`,
//! `crash_course.Pose2D`) and picks one port kind for good: small padding-free `Copy`
//! types take the seqlock path ([`CopyKind`]), everything else the pooled zero-copy
//! path ([`PooledKind`]). Because the choice belongs to the type, two modules written
//! independently always agree on it and their ports always connect.

use ferroc_ports::port::{
    CopyInputPort, CopyOutputPort, InputHandle, InputPort, NoUninit, OutputHandle, OutputPort,
    PortRef, QueueConfig,
};
use std::time::Duration;

/// A type that can be sent through ports.
///
/// Implemented for the built-in numeric types, `bool`, `String` and `Vec`s and arrays
/// of numbers; library types opt in with [`port_value!`](crate::port_value).
pub trait PortValue: Default + Send + Sync + Sized + 'static {
    /// Which port implementation carries this type.
    type Kind: PortKind<Self>;
    /// The type's name in models and manifests (`f64`, `[f64]`, `nav.Pose2D`).
    fn model_type() -> String;
}

/// How a port kind creates and uses ports for `T` (implemented by [`CopyKind`] and
/// [`PooledKind`]; module code never names it).
pub trait PortKind<T>: 'static {
    /// The concrete input port.
    type Input: Send + Sync + 'static;
    /// The concrete output port.
    type Output: Send + Sync + 'static;
    /// What reading an input gives: the value itself, or a shared reference to it
    /// (either way it borrows as `&T`, which type-erased ports rely on).
    type Read: std::borrow::Borrow<T>;
    /// A new input (queued if `queue` is given) and its handle for wiring.
    fn input(name: &str, queue: Option<QueueConfig>) -> (Self::Input, InputHandle);
    /// A new output and its handle for wiring.
    fn output(name: &str) -> (Self::Output, OutputHandle);
    /// The latest value.
    fn get(input: &Self::Input) -> Self::Read;
    /// True once per new delivery (clears the flag).
    fn take_changed(input: &Self::Input) -> bool;
    /// The oldest queued value, if any.
    fn try_pop(input: &Self::Input) -> Option<Self::Read>;
    /// The oldest queued value, waiting at most `timeout`.
    fn pop_timeout(input: &Self::Input, timeout: Duration) -> Option<Self::Read>;
    /// Publishes a value.
    fn publish(output: &Self::Output, value: T);
    /// Publishes a value filled in place (the pooled kind reuses a buffer: no copy).
    fn publish_with(output: &Self::Output, fill: impl FnOnce(&mut T));
}

/// The seqlock path for small padding-free `Copy` types.
pub struct CopyKind;
/// The pooled zero-copy path for every other type.
pub struct PooledKind;

impl<T: NoUninit + Default + Send + Sync> PortKind<T> for CopyKind {
    type Input = CopyInputPort<T>;
    type Output = CopyOutputPort<T>;
    type Read = T;
    fn input(name: &str, queue: Option<QueueConfig>) -> (Self::Input, InputHandle) {
        let port = match queue {
            Some(q) => CopyInputPort::queued(name, q),
            None => CopyInputPort::new(name),
        };
        let handle = port.handle();
        (port, handle)
    }
    fn output(name: &str) -> (Self::Output, OutputHandle) {
        let port = CopyOutputPort::new(name);
        let handle = port.handle();
        (port, handle)
    }
    fn get(input: &Self::Input) -> T {
        input.get()
    }
    fn take_changed(input: &Self::Input) -> bool {
        input.take_changed()
    }
    fn try_pop(input: &Self::Input) -> Option<T> {
        input.try_pop()
    }
    fn pop_timeout(input: &Self::Input, timeout: Duration) -> Option<T> {
        input.pop_timeout(timeout)
    }
    fn publish(output: &Self::Output, value: T) {
        output.publish(value)
    }
    fn publish_with(output: &Self::Output, fill: impl FnOnce(&mut T)) {
        let mut value = output.get();
        fill(&mut value);
        output.publish(value)
    }
}

impl<T: Default + Send + Sync + 'static> PortKind<T> for PooledKind {
    type Input = InputPort<T>;
    type Output = OutputPort<T>;
    type Read = PortRef<T>;
    fn input(name: &str, queue: Option<QueueConfig>) -> (Self::Input, InputHandle) {
        let port = match queue {
            Some(q) => InputPort::queued(name, q),
            None => InputPort::new(name),
        };
        let handle = port.handle();
        (port, handle)
    }
    fn output(name: &str) -> (Self::Output, OutputHandle) {
        let port = OutputPort::new(name);
        let handle = port.handle();
        (port, handle)
    }
    fn get(input: &Self::Input) -> PortRef<T> {
        input.get()
    }
    fn take_changed(input: &Self::Input) -> bool {
        input.take_changed()
    }
    fn try_pop(input: &Self::Input) -> Option<PortRef<T>> {
        input.try_pop()
    }
    fn pop_timeout(input: &Self::Input, timeout: Duration) -> Option<PortRef<T>> {
        input.pop_timeout(timeout)
    }
    fn publish(output: &Self::Output, value: T) {
        output.publish(value)
    }
    fn publish_with(output: &Self::Output, fill: impl FnOnce(&mut T)) {
        output.publish_with(fill)
    }
}

/// An input port field of a module: `pub distance: In<f64>`.
///
/// Created by [`Setup::input`](super::Setup::input) (or its sensor/controller
/// variants), which also records it in the module's interface and applies the queue
/// settings of the model's connection.
pub struct In<T: PortValue> {
    pub(crate) port: <T::Kind as PortKind<T>>::Input,
    /// The freshness of the link from another part feeding it, if one does.
    source: std::sync::Arc<ferroc_ports::fresh::Source>,
}

impl<T: PortValue> In<T> {
    pub(crate) fn from_port(
        port: <T::Kind as PortKind<T>>::Input,
        source: std::sync::Arc<ferroc_ports::fresh::Source>,
    ) -> Self {
        In { port, source }
    }

    /// How long ago the latest value arrived over the link from another part feeding
    /// this input (model time in lockstep). `None` when none arrived yet, or when no
    /// link feeds it (inputs fed inside the part have no age).
    pub fn age(&self) -> Option<Duration> {
        let fresh = self.source.get()?;
        fresh.age(super::Timestamp::now())
    }

    /// Whether this input is fed from another part and has nothing current: no value
    /// arrived yet, the writer's part is gone, or the link's `deadline=` passed since the
    /// latest value. Its value ([`get`](Self::get)) is then
    /// the default or the last one that arrived, not news: do not take silence for
    /// data. Always false for inputs fed inside the part.
    pub fn is_stale(&self) -> bool {
        self.source
            .get()
            .is_some_and(|f| f.is_stale(super::Timestamp::now()))
    }

    /// The latest value (the default value until something arrives).
    #[inline]
    pub fn get(&self) -> <T::Kind as PortKind<T>>::Read {
        T::Kind::get(&self.port)
    }

    /// True if a value arrived since the last call ("input changed").
    #[inline]
    pub fn changed(&self) -> bool {
        T::Kind::take_changed(&self.port)
    }

    /// The oldest queued value (inputs connected with `queue=N`); `None` when empty.
    pub fn try_pop(&self) -> Option<<T::Kind as PortKind<T>>::Read> {
        T::Kind::try_pop(&self.port)
    }

    /// The oldest queued value, waiting at most `timeout` for one.
    pub fn pop_timeout(&self, timeout: Duration) -> Option<<T::Kind as PortKind<T>>::Read> {
        T::Kind::pop_timeout(&self.port, timeout)
    }
}

/// An output port field of a module: `pub velocity: Out<f64>`.
pub struct Out<T: PortValue> {
    port: <T::Kind as PortKind<T>>::Output,
    /// Who lends this output buffers ([`Out::lend`]).
    lend: crate::lend::LendSlot,
}

impl<T: PortValue> Out<T> {
    pub(crate) fn from_port(port: <T::Kind as PortKind<T>>::Output) -> Self {
        Out {
            port,
            lend: crate::lend::LendSlot::default(),
        }
    }

    pub(crate) fn with_lend(mut self, lend: crate::lend::LendSlot) -> Self {
        self.lend = lend;
        self
    }

    /// A buffer of `len` bytes for a large value's bytes (an image's pixels), to fill
    /// in place and publish in the value: a buffer of the shared-memory pool the value
    /// then travels in, without a copy, when this output's only readers are links to
    /// other parts on this computer; plain memory otherwise (see [`crate::lend`]). Write
    /// every byte: a pool buffer may still hold an earlier value's bytes (plain memory
    /// is zeroed).
    pub fn lend(&self, len: usize) -> crate::Bytes {
        self.lend.lend(len)
    }

    /// [`lend`](Self::lend) into `data`, giving back the buffer `data` held first: in
    /// `publish_with` the value is a recycled one, whose bytes may be a pool buffer
    /// lent for an earlier value; given back before the new one is lent, the pool
    /// never holds both.
    pub fn lend_in(&self, data: &mut crate::Bytes, len: usize) {
        *data = crate::Bytes::new();
        *data = self.lend.lend(len);
    }

    /// Publishes `value` to every connected input.
    #[inline]
    pub fn publish(&self, value: T) {
        T::Kind::publish(&self.port, value)
    }

    /// Publishes a value filled in place; for large types this reuses a pooled buffer
    /// instead of moving the value.
    #[inline]
    pub fn publish_with(&self, fill: impl FnOnce(&mut T)) {
        T::Kind::publish_with(&self.port, fill)
    }
}

/// Declares a library type as a port value: `port_value!(Pose2D, "nav.Pose2D", copy)`
/// for small padding-free `Copy` types (derive `bytemuck::NoUninit`, `#[repr(C)]`), or
/// `port_value!(Map, "nav.Map", pooled)` for everything else.
#[macro_export]
macro_rules! port_value {
    ($ty:ty, $name:expr, copy) => {
        impl $crate::PortValue for $ty {
            type Kind = $crate::CopyKind;
            fn model_type() -> String {
                String::from($name)
            }
        }
    };
    ($ty:ty, $name:expr, pooled) => {
        impl $crate::PortValue for $ty {
            type Kind = $crate::PooledKind;
            fn model_type() -> String {
                String::from($name)
            }
        }
    };
}

macro_rules! builtin_copy {
    ($($ty:ty => $name:literal),*) => {$(
        port_value!($ty, $name, copy);
        impl PortValue for Vec<$ty> {
            type Kind = PooledKind;
            fn model_type() -> String {
                format!("[{}]", $name)
            }
        }
    )*};
}

builtin_copy!(f64 => "f64", f32 => "f32", i8 => "i8", i16 => "i16", i32 => "i32",
    i64 => "i64", u8 => "u8", u16 => "u16", u32 => "u32", u64 => "u64");

port_value!(super::Timestamp, "timestamp", copy);

/// `bool` has no `NoUninit` (not every bit pattern is valid), so it travels pooled.
impl PortValue for bool {
    type Kind = PooledKind;
    fn model_type() -> String {
        "bool".into()
    }
}

impl PortValue for String {
    type Kind = PooledKind;
    fn model_type() -> String {
        "string".into()
    }
}

/// Fixed arrays of copy values (`f64[3]`, a 4×4 matrix `f64[4][4]`) stay on the copy
/// path.
impl<T, const N: usize> PortValue for [T; N]
where
    T: PortValue<Kind = CopyKind> + NoUninit,
    [T; N]: Default + NoUninit,
{
    type Kind = CopyKind;
    fn model_type() -> String {
        // `f64[4][4]` is an array of 4 `f64[4]`: the outer length is written last.
        let inner = T::model_type();
        match inner.find('[') {
            Some(at) => format!("{}[{N}]{}", &inner[..at], &inner[at..]),
            None => format!("{inner}[{N}]"),
        }
    }
}

/// `duration` ports carry `std::time::Duration`, which has padding (`u64` seconds and
/// `u32` nanoseconds), so they take the pooled path.
impl PortValue for std::time::Duration {
    type Kind = PooledKind;
    fn model_type() -> String {
        "duration".into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn model_type_names() {
        assert_eq!(f64::model_type(), "f64");
        assert_eq!(<Vec<u8>>::model_type(), "[u8]");
        assert_eq!(<[f64; 3]>::model_type(), "f64[3]");
        assert_eq!(<[[f64; 4]; 2]>::model_type(), "f64[2][4]");
        assert_eq!(String::model_type(), "string");
    }
}
