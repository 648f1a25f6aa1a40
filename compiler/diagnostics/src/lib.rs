//! ferroc's lowest layer: source files and byte spans ([`source`]), findings
//! ([`diagnostic`]), the identity and documentation of a check ([`check`]) and the
//! reporter of dependency cycles that several checks share ([`cycles`]).
//!
//! Every other compiler crate builds on this one; it depends on no crate of ours.

#![forbid(unsafe_code)]

pub mod check;
pub mod cycles;
pub mod diagnostic;
pub mod source;

pub use check::CheckInfo;
