//! Data ports: lock-free, zero-copy publishing with n:m connections.
//!
//! Two kinds of ports share one API shape:
//!
//! | kind | for | `get()` returns | publishing |
//! |---|---|---|---|
//! | [`OutputPort`] / [`InputPort`] | any `T: Send + Sync + 'static` | [`PortRef<T>`] (shared, zero-copy) | fills a pooled buffer, swaps it in |
//! | [`CopyOutputPort`] / [`CopyInputPort`] | small padding-free `Copy` types ([`NoUninit`]) | `T` by value | copies into seqlock slots, no reference counting |
//!
//! ```
//! use ferroc_ports::port::{connect, ConnectOptions, InputPort, OutputPort};
//!
//! type Matrix4 = [[f64; 4]; 4];
//! let out = OutputPort::<Matrix4>::new("out");
//! let inp = InputPort::<Matrix4>::new("in");
//! connect(&out, &inp, ConnectOptions::default())?;
//! out.publish_with(|m| m[0][0] = 1.0);
//! let v = inp.get();
//! assert_eq!(v[0][0], 1.0);
//! # Ok::<(), ferroc_ports::port::ConnectError>(())
//! ```
//!
//! Where to read on: `pool.rs` (buffers, reference counts and their invariants),
//! `cell.rs` (the reader protocol), `snapshot.rs` (connection lists that change without
//! blocking publishers), `wiring.rs` (connect/disconnect, initial push), `queue.rs`
//! (input queues and blocking), `copy.rs` + `seqlock.rs` (the `Copy` path), `local.rs`
//! + `copy_local.rs` (connections inside one thread container, without atomics).

mod cell;
mod copy;
mod copy_local;
mod handle;
mod inline;
mod input;
mod local;
mod notify;
mod output;
mod pool;
mod port_ref;
mod queue;
mod seqlock;
mod snapshot;
mod wakeup;
mod wiring;
mod words;

pub use bytemuck::NoUninit;
#[doc(hidden)]
pub use copy::CopyPeek;
pub use copy::{CopyInputPort, CopyOutputPort};
pub use handle::{InputHandle, OutputHandle};
pub use inline::{Arrival, InlineGate};
pub use input::InputPort;
pub use local::{Home, Session};
pub use notify::{Notifier, Notify, WaitMode, Wakeup};
pub use output::OutputPort;
pub use pool::PoolStats;
pub use port_ref::{BufferMut, PortRef};
pub use queue::{OnFull, QueueConfig};
#[doc(hidden)]
pub use wiring::LocalPair;
pub use wiring::{ConnectError, ConnectOptions};

/// An output that can be connected to inputs of type `I`.
///
/// Implemented for [`OutputPort<T>`] → [`InputPort<T>`] and [`CopyOutputPort<T>`] →
/// [`CopyInputPort<T>`]; connecting ports of different value types does not compile.
pub trait Connect<I> {
    /// See [`connect`].
    fn connect_to(&self, input: &I, options: ConnectOptions) -> Result<(), ConnectError>;
    /// See [`disconnect`].
    fn disconnect_from(&self, input: &I) -> bool;
}

/// Connects `output` to `input`: from now on every value published on `output` is
/// delivered to `input` as well. Never blocks publishers; an output may feed many
/// inputs and an input may have many outputs (the last delivery wins).
pub fn connect<O: Connect<I>, I>(
    output: &O,
    input: &I,
    options: ConnectOptions,
) -> Result<(), ConnectError> {
    output.connect_to(input, options)
}

/// Makes the connection `output → input` local to the thread container that owns
/// `home`: its value then lives in a plain cell that only the thread holding `home`'s
/// [`Session`] touches (`port/local.rs`). True if it became local; false leaves it on
/// the lock-free path (not connected, a queued input, an input with other sources, an
/// output local to another home, or the container did not reach a cycle boundary in
/// time). The Builder does this at start for connections the plan marks as inside one
/// container.
pub fn make_local<T: NoUninit + Send + Sync>(
    output: &CopyOutputPort<T>,
    input: &CopyInputPort<T>,
    home: &crate::sync::Arc<Home>,
) -> bool {
    copy_local::make_local(&output.core, &input.core, home)
}

/// Removes the connection; false if the ports were not connected. Never blocks
/// publishers; a publish already under way may still deliver its value once.
pub fn disconnect<O: Connect<I>, I>(output: &O, input: &I) -> bool {
    output.disconnect_from(input)
}

impl<T: Send + Sync + 'static> Connect<InputPort<T>> for OutputPort<T> {
    fn connect_to(
        &self,
        input: &InputPort<T>,
        options: ConnectOptions,
    ) -> Result<(), ConnectError> {
        wiring::connect(&self.core, &input.core, options)
    }
    fn disconnect_from(&self, input: &InputPort<T>) -> bool {
        wiring::disconnect(&self.core, &input.core)
    }
}

impl<T: NoUninit + Send + Sync> Connect<CopyInputPort<T>> for CopyOutputPort<T> {
    fn connect_to(
        &self,
        input: &CopyInputPort<T>,
        options: ConnectOptions,
    ) -> Result<(), ConnectError> {
        wiring::connect(&self.core, &input.core, options)
    }
    fn disconnect_from(&self, input: &CopyInputPort<T>) -> bool {
        wiring::disconnect(&self.core, &input.core)
    }
}

#[cfg(test)]
mod local_tests;
#[cfg(test)]
mod tests;
