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
//!
//! Modules: [`server`] (the queryable a program serves, on its own thread), [`token`]
//! (the token changes need), [`limits`] (what one client of the web page or the
//! Foxglove bridge may cost), [`structure`] (the `edit` and `model` keys, answered by the
//! runner's `Structure`), [`request`] (the keys and requests), [`config`] (session
//! configuration: loopback by default, explicit endpoints, no multicast), [`client`]
//! (what `ferroc inspect` asks with), [`param_value`] (a parameter change's text parsed
//! as a model file's value would be, shared by `ferroc run` and bundles), [`program`]
//! (what a bundle's part program calls for `--inspect`), [`web`] (the web page of
//! `ferroc inspect --serve`: an axum server with the client as its Zenoh peer; behind
//! the feature `web`, which only the CLI enables) and,
//! behind the feature `foxglove`, `foxglove` (`ferroc inspect --foxglove`: a bridge to
//! the Foxglove WebSocket protocol).

#![forbid(unsafe_code)]

pub mod client;
pub mod config;
#[cfg(feature = "foxglove")]
pub mod foxglove;
pub mod limits;
pub mod param_value;
pub mod program;
pub mod request;
pub mod server;
pub mod structure;
pub mod token;
#[cfg(feature = "web")]
pub mod web;
