//! Simulated time: the step of each module type.
//!
//! The runtime gives a module no clock (and a wall clock would make runs differ), so
//! each module type advances its simulation by the period of the thread container it
//! is meant for in `models/warehouse_fleet.xml`. Placed in a container of another
//! period, it still works, only faster or slower in model time.

/// The hardware layer (`io`, 10 ms): kinematics, motors, scanner, battery, lift.
pub const IO_STEP: f64 = 0.01;
/// Order intake and dispatch (`dispatch`, 200 ms): WMS bridge and fleet manager.
pub const DISPATCH_STEP: f64 = 0.2;
/// The dashboard (`monitoring`, 500 ms).
pub const MONITOR_STEP: f64 = 0.5;
