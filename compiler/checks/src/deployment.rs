//! Checks of area deployment.

pub mod x101_part_without_threads;
pub mod x102_invalid_host_label;
pub mod x103_host_label_conflict;
pub mod x104_pointless_connection_settings;
pub mod x105_bundle_output_collision;
pub mod x106_nondeterministic_in_lockstep;
