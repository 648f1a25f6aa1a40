//! Live inspection of a running ferroc application over Eclipse Zenoh (docs/inspect.md).
//!
//! A part program serves what its [`Inspector`](ferroc_runtime::inspect::Inspector)
//! knows under `ferroc/APP/inspect/PART/…` ([`server`]): the element tree, each port's
//! latest value, parameters, container figures, link state and iB2C activities, as
//! JSON answers to Zenoh queries. A parameter change is a query carrying the new value
//! and the token the program printed at start; it is checked (type, unit, range)
//! before it is applied. `ferroc inspect` is the [`client`]: a Zenoh peer that connects
//! to explicit endpoints (multicast scouting off) and asks.
//!
//! Nothing is published while nobody asks: every answer is computed when a query
//! arrives, so an idle inspector costs the application nothing.

pub mod client;
pub mod config;
#[cfg(feature = "foxglove")]
pub mod foxglove;
pub mod param_value;
pub mod program;
pub mod request;
pub mod server;
pub mod structure;
pub mod token;
pub mod web;
