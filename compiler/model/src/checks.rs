//! The checks raised while loading files, reading library manifests and resolving the
//! model (areas M, L, P, and B101, T102 for what the resolver already knows): code,
//! name, severity and explanation, each in its file with its fixtures in the folder of
//! the same name. The checks of the reader and validator (`ferroc_syntax::checks`) are
//! re-exported here, so the model's code names every check it raises from one place.

pub use ferroc_syntax::checks::*;

pub mod b101_meta_constant_out_of_range;
pub mod l101_unknown_library;
pub mod l102_invalid_manifest;
pub mod l103_dependency_cycle;
pub mod l104_library_not_used;
pub mod l105_conflicting_library;
pub mod m101_malformed_xml;
pub mod m109_duplicate_name;
pub mod m110_unresolved_path;
pub mod m111_unknown_type;
pub mod m113_include_outside_root;
pub mod m114_include_cycle;
pub mod m115_file_not_found;
pub mod m117_recursive_group_type;
pub mod m119_wrong_root_element;
pub mod p103_unparsable_value;
pub mod p104_out_of_range;
pub mod p105_wrong_unit_dimension;
pub mod p106_config_entry_missing;
pub mod t102_incompatible_types;
