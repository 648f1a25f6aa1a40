//! Checks of area model.

pub use ferroc_model::checks::m101_malformed_xml;
pub use ferroc_model::checks::m109_duplicate_name;
pub use ferroc_model::checks::m110_unresolved_path;
pub use ferroc_model::checks::m111_unknown_type;
pub use ferroc_syntax::checks::m102_unknown_element;
pub use ferroc_syntax::checks::m103_unknown_attribute;
pub use ferroc_syntax::checks::m104_missing_attribute;
pub use ferroc_syntax::checks::m105_misplaced_element;
pub use ferroc_syntax::checks::m106_duplicate_attribute;
pub use ferroc_syntax::checks::m107_invalid_name;
pub use ferroc_syntax::checks::m108_invalid_attribute_value;
pub mod m112_module_not_executed;
pub use ferroc_model::checks::m113_include_outside_root;
pub use ferroc_model::checks::m114_include_cycle;
pub use ferroc_model::checks::m115_file_not_found;
pub use ferroc_model::checks::m117_recursive_group_type;
pub use ferroc_model::checks::m119_wrong_root_element;
pub use ferroc_syntax::checks::m116_limit_exceeded;
