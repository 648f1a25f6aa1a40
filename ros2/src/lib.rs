//! ROS 2 on the same wire as rmw_zenoh: the foundations a part needs to speak to ROS 2
//! nodes (issue 29).
//!
//! - [`parse`]: ROS 2 interface definitions (`.msg`, `.srv`) read from their own text
//!   format into [`def`] data; [`Registry`] holds the shipped packages (std_msgs,
//!   builtin_interfaces, geometry_msgs, sensor_msgs, nav_msgs, std_srvs, service_msgs)
//!   and any a team adds by pointing at its folders, and resolves nested types.
//! - [`hash`]: RIHS01 type hashes computed from the type description (REP-2016), as
//!   rosidl computes them.
//! - [`cdr`]: XCDR1 little-endian encoding and decoding of a dynamic [`Value`] of any
//!   registered type, bounded against hostile input; [`serde_cdr`]: the same straight
//!   from a port's own (serde) value and back, what a running part sends. Both follow
//!   CDR's rules as `wire.rs` writes them once.
//! - [`names`]: the node, namespace and topic names ROS 2 accepts, and how a relative
//!   topic name expands against a node's namespace.
//! - [`json`]: a value's serde JSON as a message of a type, and back (tools, tests).
//! - [`mcap_schema`]: a message type's schema text as MCAP's `ros2msg` encoding holds it
//!   (recordings of ROS-typed ports).
//! - [`units`]: the units REP-103 fixes for fields of the shipped messages.
//! - [`rmw_zenoh`]: the topic key expression, the attachment and the liveliness tokens
//!   exactly as rmw_zenoh writes them.
//!
//! This crate depends on nothing of ours: the model, the checks and the runtime use it.
#![forbid(unsafe_code)]

pub mod cdr;
pub mod def;
mod error;
pub mod hash;
pub mod json;
pub mod mcap_schema;
pub mod names;
pub mod parse;
mod registry;
pub mod rmw_zenoh;
pub mod serde_cdr;
pub mod units;
mod value;
mod wire;

pub use error::DefinitionError;
pub use registry::{Registry, TeamFile};
pub use value::Value;
