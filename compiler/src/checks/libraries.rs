//! Checks of area libraries.

pub mod l101_unknown_library;
pub mod l102_invalid_manifest;
pub mod l103_dependency_cycle;
pub mod l104_library_not_used;
pub mod l105_conflicting_library;
pub mod l106_make_cycle;
pub mod l107_duplicate_make_lib;
