//! Checks of area connections.

pub mod t101_wrong_direction;
pub mod t102_incompatible_types;
pub mod t103_unit_dimension_mismatch;
pub mod t104_implicit_unit_scale;
pub mod t105_unit_on_one_end;
pub mod t106_narrowing_without_convert;
pub mod t107_duplicate_connection;
pub mod t108_multiple_writers;
pub mod t109_required_input_unconnected;
pub mod t110_unused_output;
pub mod t111_not_serialisable_across_parts;
pub mod t112_double_scaling;
pub mod t113_invalid_convert;
