//! What runs and what changes: the run [`plan`] of a checked model (modules with parsed
//! parameters, connections, thread containers, links between parts) that `ferroc run`
//! and bundles build from, and structural [`edit`]s of a model's text with the plan
//! difference a running application applies.
//!
//! Depends on `ferroc-diagnostics`, `ferroc-values`, `ferroc-syntax`, `ferroc-model`
//! and `ferroc-schedule`; on `ferroc-ros2` for ROS 2's topic names (`plan/ros2.rs`).

#![forbid(unsafe_code)]

pub mod edit;
pub mod plan;
