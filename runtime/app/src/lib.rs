//! The top of ferroc's runtime: an application as a whole.
//!
//! * [`builder`] — the [`Builder`](builder::Builder) creates module instances from a
//!   [`Registry`](builder::Registry), connects their ports, services and links, takes
//!   the model's locks and thread containers, and starts it all as a
//!   [`RunningApp`](builder::RunningApp); a running application can be reconfigured
//!   (modules and connections added and removed) between cycles.
//! * [`inspect`] — a read-only look into a running application (element tree, each
//!   port's latest value on request, parameters, container figures, link state, iB2C
//!   activities) and checked parameter changes: what `ferroc inspect` shows.
//! * [`supervise`] — running a started application until its cycle limit, a time limit
//!   or Ctrl-C, with a live status line and a summary: shared by `ferroc run` and the
//!   programs of a `ferroc bundle`.
//!
//! It depends on every other runtime crate (`ferroc-ports`, `ferroc-module`,
//! `ferroc-exec`, `ferroc-link`); none of them depends on it.

#![forbid(unsafe_code)]
#![warn(missing_docs)]

/// `eprintln!` that does not panic when standard error is closed or full (see
/// `ferroc_ports::console::stderr_line`); it shadows std's in this whole crate.
macro_rules! eprintln {
    ($($arg:tt)*) => {
        ferroc_ports::console::stderr_line(format_args!($($arg)*))
    };
}

pub mod builder;
pub mod inspect;
pub mod supervise;
#[cfg(any(test, feature = "test-support"))]
#[doc(hidden)]
pub mod test_support;
