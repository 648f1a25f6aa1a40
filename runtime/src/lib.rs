//! ferroc's runtime: what a checked application model runs on.
//!
//! This crate only re-exports the runtime crates under the paths generated bundles,
//! component libraries and users' crates name (`ferroc_runtime::port::…`,
//! `ferroc_runtime::module::…`, …). The runtime itself is five crates, each on the ones
//! below it (ARCHITECTURE.md, "Inside the runtime"):
//!
//! * `ferroc-ports` — [`port`], [`service`], [`console`]: data ports and services, with
//!   timestamps, link freshness, the stop flag and thread placement they need;
//! * `ferroc-module` — [`module`], [`behaviour`], [`resource`]: the module API, iB2C
//!   behaviours, the model's locks;
//! * `ferroc-exec` — [`container`]: thread containers running a static step order;
//! * `ferroc-link` — [`link`]: connections between parts;
//! * `ferroc-app` — [`builder`], [`inspect`], [`supervise`]: building, starting,
//!   inspecting, supervising and reconfiguring an application.

#![forbid(unsafe_code)]
#![warn(missing_docs)]

#[cfg(feature = "test-support")]
#[doc(hidden)]
pub use ferroc_app::test_support;
pub use ferroc_app::{builder, inspect, supervise};
pub use ferroc_exec as container;
pub use ferroc_link as link;
pub use ferroc_module as module;
pub use ferroc_module::{behaviour, port_value, resource};
pub use ferroc_ports::{console, port, service};

/// Compiles and runs the Rust examples of `docs/runtime-services.md` (which name the
/// paths of this facade), so that the module writers' guide cannot drift from the API.
#[cfg(doctest)]
#[doc = include_str!("../../docs/runtime-services.md")]
struct RuntimeServicesGuide;
