//! Units, value types and parameter values: what the model language writes after a
//! port's `type=`/`unit=` and inside `<param>`. The compiler checks with it; part
//! programs parse parameter values with it, so both agree.
//!
//! Depends on no crate of ours.

#![forbid(unsafe_code)]

pub mod types;
pub mod units;
pub mod values;
