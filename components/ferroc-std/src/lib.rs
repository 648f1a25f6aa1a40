//! The standard module library of ferroc (manifest: `components/ferroc_std.lib.xml`,
//! built into the `ferroc` binary).
//!
//! Implemented: `Constant`, `Scale`, `NumberToActivity`, `ConstantActivity` and the
//! iB2C fusion `Fusion` (f64 data), whose machinery ([`fusion`]) fuses any data type
//! that implements [`fusion::Fuse`] and is what library fusions (a velocity fusion of
//! two ports per channel, say) are built from.
//!
//! Not implemented yet: the flexible types (`Sum`, `FlexiSelect`, `Dump`, `Logger`),
//! whose ports the instance declares (the runtime has no per-instance port types yet),
//! and `Clock` (the runtime has no `timestamp` port type yet).

mod basic;
pub mod fusion;

pub use basic::{Constant, ConstantActivity, NumberToActivity, Scale};
pub use fusion::Fusion;

use ferroc_runtime::builder::Registry;

/// Registers every implemented module type of `ferroc_std`.
pub fn register(registry: &mut Registry) {
    registry
        .register::<Constant>()
        .register::<Scale>()
        .register::<NumberToActivity>()
        .register::<ConstantActivity>()
        .register_behaviour::<Fusion>();
}
