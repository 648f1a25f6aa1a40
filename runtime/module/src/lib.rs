//! The module API: what a hand-written module looks like.
//!
//! A module is a plain Rust struct whose fields are its ports ([`In`], [`Out`]) and
//! parameters ([`Parameter`]), plus whatever state it needs. It implements [`Module`]
//! (what it does each cycle) and [`ModuleType`] (its model name and how to create it).
//! `create` declares each port and parameter while creating it, so the interface the
//! runtime reports (and `ferroc types export` writes) is exactly what the code owns.
//! See `docs/writing-modules.md` for a complete walk-through.
//!
//! Besides the module API this crate holds what modules are built from and with:
//! [`behaviour`] (the iB2C behaviour base), [`resource`] (the model's locks),
//! [`violations`] (the log of broken iB2C principles), [`cycle`] (what a step can ask
//! about its cycle: the container's period), each module's [`Random`] source
//! and what the run knows of its reproducibility ([`Determinism`]), the [`ValueTable`] (every value
//! type, how it is shown, encoded and connected) and the [`Codec`] (postcard).
//! It depends on `ferroc-ports` only.

#![forbid(unsafe_code)]
#![warn(missing_docs)]

/// `eprintln!` that does not panic when standard error is closed or full (see
/// `ferroc_ports::console::stderr_line`); it shadows std's in this whole crate.
#[allow(unused_macros)] // nothing prints with it today; kept so that nothing uses std's
macro_rules! eprintln {
    ($($arg:tt)*) => {
        ferroc_ports::console::stderr_line(format_args!($($arg)*))
    };
}

pub mod behaviour;
pub mod bytes;
pub mod cycle;
pub mod lend;
pub mod resource;
pub mod violations;

mod codec;
mod data_loss;
mod determinism;
mod flexible;
mod interface;
mod param;
mod random;
mod ros2_message;
mod services;
#[doc(hidden)]
pub mod setup;
mod value;
mod value_table;

pub use bytes::Bytes;
pub use codec::{Codec, Encoder};
pub use data_loss::{data_losses, report_data_loss};
pub use determinism::{Determinism, Nondeterminism, WallClock};
pub use ferroc_ports::time::Timestamp;
pub use flexible::{FlexibleDecl, PortGroup, MAX_GROUP_PORTS};
pub use interface::{
    Direction, FlexibleInfo, Interface, Kind, MetaType, ParamInfo, PortInfo, Role, ServiceInfo,
};
pub use param::{ParamHandle, ParamValue, Parameter, Value};
pub use random::{seed_from_os, Random};
pub use ros2_message::{Ros2Message, Ros2Meta};
pub use services::{ClientDecl, ServiceDecl};
pub use setup::{InputDecl, OutputDecl, ParamDecl, PortDecl, Setup};
pub use value::{CopyKind, In, Out, PooledKind, PortKind, PortValue};
pub use value_table::{
    ArrayText, DebugText, DynIn, DynOut, Number, NumberArray, NumberText, PlainText, ValueTable,
    ValueText, ValueType,
};
/// The former name of [`Codec`], kept for the crates that name it.
pub type Wire = Codec;

/// What a module does in a cycle. Plain modules implement `update`; sense-control
/// modules `sense` (read sensor inputs, publish sensor outputs) and `control` (read
/// controller inputs, publish commands). Unused methods keep their empty default.
pub trait Module: Send + 'static {
    /// The step of a plain module.
    fn update(&mut self) {}
    /// The sensing step of a sense-control module.
    fn sense(&mut self) {}
    /// The control step of a sense-control module.
    fn control(&mut self) {}
}

/// A module type the runtime can create by name.
pub trait ModuleType: Module + Sized {
    /// Qualified model name: `library.Type` (`crash_course.AddNoise`).
    const NAME: &'static str;
    /// Plain (`update`) or sense-control (`sense` + `control`).
    const KIND: Kind = Kind::Plain;
    /// One-line description for the manifest.
    const DOC: &'static str = "";

    /// Creates an instance: declare and create every port and parameter through `m`.
    /// Keep it free of side effects (no files, no hardware): the registry also calls
    /// it to learn the interface. Do such work lazily in the first step.
    fn create(m: &mut Setup<'_>) -> Self;
}

/// The payload with which a module asks to be stopped (unwound with
/// [`std::panic::resume_unwind`], so no panic message is printed): the container reports
/// the text with the step's name and stops the step, as it does after a panic.
#[derive(Debug)]
pub struct StopStep(pub String);
