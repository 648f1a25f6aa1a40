//! The checks raised while reading and validating a file (area M): code, name,
//! severity and explanation, each in its file with its fixtures in the folder of the
//! same name. The loader and resolver raise more of area M (`ferroc_model::checks`).

pub mod m102_unknown_element;
pub mod m103_unknown_attribute;
pub mod m104_missing_attribute;
pub mod m105_misplaced_element;
pub mod m106_duplicate_attribute;
pub mod m107_invalid_name;
pub mod m108_invalid_attribute_value;
pub mod m116_limit_exceeded;
