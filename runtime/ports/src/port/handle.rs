//! Type-erased handles on ports, for wiring by name.
//!
//! Modules own their ports as typed struct fields, but whoever wires an application
//! from a model (the runtime `Builder`) only knows port *names*. A handle shares the
//! port's core (not the port: dropping the port still disconnects it) and remembers,
//! as a plain function pointer monomorphised for the value type, how to connect it.
//! Connecting two handles of different value types is an error value, not a panic.

use super::copy::{CopyInputCore, CopyOutputCore};
use super::input::InputCore;
use super::output::OutputCore;
use super::wiring::{self, InCore, OutCore};
use super::{ConnectError, ConnectOptions, Notifier};
use super::{CopyInputPort, CopyOutputPort, InputPort, NoUninit, OutputPort};
use crate::sync::Arc;
use std::any::Any;

type ConnectFn = fn(&OutputHandle, &InputHandle, ConnectOptions) -> Result<(), ConnectError>;
type DisconnectFn = fn(&OutputHandle, &InputHandle) -> bool;
type PairFn = fn(&OutputHandle, &InputHandle) -> Option<super::LocalPair>;

/// A shared, type-erased reference to an output port's core.
pub struct OutputHandle {
    /// `Arc<O>` for the port's core type `O`.
    core: Box<dyn Any + Send + Sync>,
    value_type: &'static str,
    name: String,
    connect: ConnectFn,
    disconnect: DisconnectFn,
    pair: PairFn,
}

/// A shared, type-erased reference to an input port's core.
pub struct InputHandle {
    /// `Arc<I>` for the port's core type `I`.
    core: Box<dyn Any + Send + Sync>,
    value_type: &'static str,
    name: String,
    set_notifier: fn(&InputHandle, Notifier) -> Result<(), Notifier>,
    /// The freshness of the link feeding the port, if one does (shared with the
    /// module's `In`). Plain `std` `Arc`: freshness is link bookkeeping outside the
    /// port core that loom models.
    source: std::sync::Arc<crate::fresh::Source>,
}

impl OutputHandle {
    fn new<O: OutCore>(core: &Arc<O>, value_type: &'static str) -> Self {
        OutputHandle {
            name: core.name().to_owned(),
            core: Box::new(core.clone()),
            value_type,
            connect: connect_cores::<O>,
            disconnect: disconnect_cores::<O>,
            pair: pair_cores::<O>,
        }
    }

    /// The Rust type of the values (for messages).
    pub fn value_type(&self) -> &'static str {
        self.value_type
    }

    /// The port's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Connects like [`connect`](super::connect); an input of another value type or
    /// port kind gives [`ConnectError::TypeMismatch`].
    pub fn connect(
        &self,
        input: &InputHandle,
        options: ConnectOptions,
    ) -> Result<(), ConnectError> {
        (self.connect)(self, input, options)
    }

    /// Disconnects; false if not connected (or not connectable at all).
    pub fn disconnect(&self, input: &InputHandle) -> bool {
        (self.disconnect)(self, input)
    }

    /// What makes the connection to `input` local to a thread container later (the
    /// Builder, at start); `None` for port kinds without a local path or ports of other
    /// types.
    #[doc(hidden)]
    pub fn local_pair(&self, input: &InputHandle) -> Option<super::LocalPair> {
        (self.pair)(self, input)
    }
}

impl InputHandle {
    fn new<I: InCore + HasNotifier>(core: &Arc<I>, value_type: &'static str) -> Self {
        InputHandle {
            name: core.name().to_owned(),
            core: Box::new(core.clone()),
            value_type,
            set_notifier: set_notifier_erased::<I>,
            source: std::sync::Arc::default(),
        }
    }

    /// Where the link feeding this port (if any) keeps its freshness.
    #[doc(hidden)]
    pub fn source(&self) -> std::sync::Arc<crate::fresh::Source> {
        std::sync::Arc::clone(&self.source)
    }

    /// The Rust type of the values (for messages).
    pub fn value_type(&self) -> &'static str {
        self.value_type
    }

    /// The port's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Registers the notifier every delivery calls (a data-triggered container's wakeup).
    pub fn set_notifier(&self, notifier: Notifier) -> Result<(), Notifier> {
        (self.set_notifier)(self, notifier)
    }
}

fn cores<'a, O: OutCore>(
    output: &'a OutputHandle,
    input: &'a InputHandle,
) -> Option<(&'a Arc<O>, &'a Arc<O::In>)> {
    Some((
        output.core.downcast_ref::<Arc<O>>()?,
        input.core.downcast_ref::<Arc<O::In>>()?,
    ))
}

fn connect_cores<O: OutCore>(
    output: &OutputHandle,
    input: &InputHandle,
    options: ConnectOptions,
) -> Result<(), ConnectError> {
    match cores::<O>(output, input) {
        Some((out, inp)) => wiring::connect(out, inp, options),
        None => Err(ConnectError::TypeMismatch {
            output: format!("{} ({})", output.name, output.value_type),
            input: format!("{} ({})", input.name, input.value_type),
        }),
    }
}

fn pair_cores<O: OutCore>(output: &OutputHandle, input: &InputHandle) -> Option<super::LocalPair> {
    let (out, inp) = cores::<O>(output, input)?;
    O::local_pair(out, inp)
}

fn disconnect_cores<O: OutCore>(output: &OutputHandle, input: &InputHandle) -> bool {
    cores::<O>(output, input).is_some_and(|(out, inp)| wiring::disconnect(out, inp))
}

fn set_notifier_erased<I: InCore + HasNotifier>(
    input: &InputHandle,
    notifier: Notifier,
) -> Result<(), Notifier> {
    match input.core.downcast_ref::<Arc<I>>() {
        Some(core) => core.set_notifier(notifier),
        None => Err(notifier),
    }
}

/// Input cores that accept a wakeup notifier.
pub(crate) trait HasNotifier {
    fn set_notifier(&self, notifier: Notifier) -> Result<(), Notifier>;
}

impl<T: Send + Sync + 'static> OutputPort<T> {
    /// A type-erased handle for wiring by name.
    pub fn handle(&self) -> OutputHandle {
        OutputHandle::new::<OutputCore<T>>(&self.core, std::any::type_name::<T>())
    }
}

impl<T: Send + Sync + 'static> InputPort<T> {
    /// A type-erased handle for wiring by name.
    pub fn handle(&self) -> InputHandle {
        InputHandle::new::<InputCore<T>>(&self.core, std::any::type_name::<T>())
    }
}

impl<T: NoUninit + Send + Sync> CopyOutputPort<T> {
    /// A type-erased handle for wiring by name.
    pub fn handle(&self) -> OutputHandle {
        OutputHandle::new::<CopyOutputCore<T>>(&self.core, std::any::type_name::<T>())
    }
}

impl<T: NoUninit + Send + Sync> CopyInputPort<T> {
    /// A type-erased handle for wiring by name.
    pub fn handle(&self) -> InputHandle {
        InputHandle::new::<CopyInputCore<T>>(&self.core, std::any::type_name::<T>())
    }
}

impl std::fmt::Debug for OutputHandle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "OutputHandle({}: {})", self.name, self.value_type)
    }
}

impl std::fmt::Debug for InputHandle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "InputHandle({}: {})", self.name, self.value_type)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn handles_connect_ports_of_one_type() {
        let out = CopyOutputPort::<f64>::new("out");
        let inp = CopyInputPort::<f64>::new("in");
        out.handle()
            .connect(&inp.handle(), ConnectOptions::default())
            .unwrap();
        out.publish(2.5);
        assert_eq!(inp.get(), 2.5);
        assert!(out.handle().disconnect(&inp.handle()));
        out.publish(3.0);
        assert_eq!(inp.get(), 2.5);
    }

    #[test]
    fn handles_of_different_types_do_not_connect() {
        let out = CopyOutputPort::<f64>::new("speed");
        let inp = CopyInputPort::<u32>::new("count");
        let err = out
            .handle()
            .connect(&inp.handle(), ConnectOptions::default())
            .unwrap_err();
        assert_eq!(
            err.to_string(),
            "cannot connect `speed (f64)` to `count (u32)`: the value types differ"
        );
        // Same value type, other port kind: also refused.
        let pooled = InputPort::<f64>::new("pooled");
        assert!(out
            .handle()
            .connect(&pooled.handle(), ConnectOptions::default())
            .is_err());
    }

    #[test]
    fn a_handle_outliving_its_port_is_harmless() {
        let out = OutputPort::<Vec<u8>>::new("out");
        let handle = out.handle();
        let inp = InputPort::<Vec<u8>>::new("in");
        drop(out);
        // The core is still alive: connecting works but nothing will ever be published.
        handle
            .connect(&inp.handle(), ConnectOptions::default())
            .unwrap();
        assert!(inp.get().is_empty());
    }
}
