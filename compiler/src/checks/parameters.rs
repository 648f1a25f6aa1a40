//! Checks of area parameters.

pub mod p101_unknown_parameter;
pub mod p102_missing_required_parameter;
pub mod p103_unparsable_value;
pub mod p104_out_of_range;
pub mod p105_wrong_unit_dimension;
pub mod p106_config_entry_missing;
pub mod p107_duplicate_parameter;
pub mod p108_invalid_pin_map;
pub mod p109_const_value_type;
