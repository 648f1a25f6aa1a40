//! The standard module library of ferroc (manifest: `components/ferroc_std.lib.xml`,
//! built into the `ferroc` binary).
//!
//! Implemented: `Constant`, `Scale`, `NumberToActivity`, `ConstantActivity` and the
//! iB2C fusion `Fusion` (f64 data), whose machinery ([`fusion`]) fuses any data type
//! that implements [`fusion::Fuse`] and is what library fusions (a velocity fusion of
//! two ports per channel, say) are built from.
//!
//! The flexible types `Sum`, `FlexiSelect`, `Dump`, `Const`, `Filter`, `Logger` and
//! `Player` take the ports their instance declares in the model, of any type in the
//! runtime's value-type table (`flexible.rs`, `constant.rs`, `filter.rs`, `logger.rs`,
//! `player.rs`); `Logger` records into MCAP files and `Player` replays them
//! ([`recording`], docs/recording-and-utilities.md); `Clock` publishes `timestamp`s and
//! a tick count.
//! `ScaleService` and `Ask` are the smallest service and client (`services.rs`).
//! [`Image`] and [`PointCloud`] carry large data (`large/`; as ROS 2 messages `large/ros2.rs`).

#![forbid(unsafe_code)]

/// `eprintln!` that does not panic when standard error is closed or full (see
/// `ferroc_runtime::console::stderr_line`); it shadows std's in this whole crate.
macro_rules! eprintln {
    ($($arg:tt)*) => {
        ferroc_runtime::console::stderr_line(format_args!($($arg)*))
    };
}

mod basic;
mod constant;
mod filter;
mod flexible;
pub mod fusion;
pub mod large;
mod logger;
mod player;
pub mod recorder;
pub mod recording;
mod services;

pub use basic::{Constant, ConstantActivity, NumberToActivity, Scale};
pub use constant::Const;
pub use filter::Filter;
pub use flexible::{Add, Clock, Dump, FlexiSelect, Sum};
pub use fusion::Fusion;
pub use large::{Image, PointCloud, PointField};
pub use logger::{check_log_path, Logger};
pub use player::Player;
pub use recorder::{Recordable, Recorder, Recorders};
pub use services::{Ask, ScaleService};

use ferroc_runtime::builder::Registry;

/// Registers every implemented module type of `ferroc_std`.
pub fn register(registry: &mut Registry) {
    registry
        .register::<Constant>()
        .register::<Scale>()
        .register::<NumberToActivity>()
        .register::<ConstantActivity>()
        .register::<Clock>()
        .register::<Sum>()
        .register::<Add>()
        .register::<FlexiSelect>()
        .register::<Dump>()
        .register::<Logger>()
        .register::<Player>()
        .register::<Const>()
        .register::<Filter>()
        .register::<ScaleService>()
        .register::<Ask>()
        // `Ask` may call a `ScaleService` in another part.
        .register_call::<f64, f64>()
        // Large data, across parts, in recordings, and as sensor_msgs/Image and
        // PointCloud2 on ROS 2 topics (large/ros2.rs).
        .register_ros2::<Image>()
        .register_ros2::<PointCloud>()
        .register_behaviour::<Fusion>();
}
