//! Checks of area model.

pub mod m101_malformed_xml;
pub mod m102_unknown_element;
pub mod m103_unknown_attribute;
pub mod m104_missing_attribute;
pub mod m105_misplaced_element;
pub mod m106_duplicate_attribute;
pub mod m107_invalid_name;
pub mod m108_invalid_attribute_value;
pub mod m109_duplicate_name;
pub mod m110_unresolved_path;
pub mod m111_unknown_type;
pub mod m112_module_not_executed;
pub mod m113_include_outside_root;
pub mod m114_include_cycle;
pub mod m115_file_not_found;
pub mod m116_limit_exceeded;
pub mod m117_recursive_group_type;
pub mod m118_unknown_code_in_allow;
pub mod m119_wrong_root_element;
