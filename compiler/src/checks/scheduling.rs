//! Checks of area scheduling and timing (S).

pub mod s101_data_flow_loop;
