//! ferroc's runtime: what a checked application model runs on.
//!
//! This crate grows with the runtime issue (modules, thread containers, parts, iB2C,
//! introspection). Today it holds the data-port core, services and thread containers:
//!
//! * [`container`] — one OS thread per thread container, executing the compiler's static
//!   step order periodically (absolute deadlines, overrun counting) or when data
//!   arrives; per-step timing statistics; a panicking step is stopped, the rest run on.
//! * [`port`] — output and input ports, buffer pools, n:m connections, input queues,
//!   data-triggered wakeups. Publishing is lock-free and zero-copy; connections change
//!   at run time without blocking publishers.
//! * [`resource`] — the model's `<resource>` locks as real locks, with lockdep-style
//!   validation: an acquisition order that contradicts one seen before (or the
//!   declared one) is reported with both sites before it can deadlock.
//! * [`behaviour`] — the iB2C behaviour base: meta ports, activation, and the runtime
//!   principles (activity limitation, goal state, …) checked every cycle under a
//!   per-module policy (`warn`, `clamp`, `stop`).
//! * [`service`] — request/response ports: a service executed by the serving module's
//!   thread container (or inline by its callers), blocking and asynchronous clients
//!   with optional timeouts; every failure is an error value, never a hang.
//! * [`inspect`] — a read-only look into a running application (element tree, each
//!   port's latest value on request, parameters, container figures, link state, iB2C
//!   activities) and checked parameter changes: what `ferroc inspect` shows.
//! * [`supervise`] — running a started application until its cycle limit, a time limit
//!   or Ctrl-C, with a live status line and a summary: shared by `ferroc run` and the
//!   programs of a `ferroc bundle`.
//!
//! The crate does not depend on the compiler. Its concurrency is verified with loom
//! (`RUSTFLAGS="--cfg loom" cargo test -p ferroc-runtime --release --test loom_ports
//! --test loom_services`)
//! and Miri (`cargo +nightly miri test -p ferroc-runtime --lib`); `runtime/verify.sh`
//! runs both.

#![warn(missing_docs)]

/// `eprintln!` that does not panic when standard error is closed or full (see
/// `ferroc_runtime::console::stderr_line`); it shadows std's in this whole crate.
macro_rules! eprintln {
    ($($arg:tt)*) => {
        $crate::console::stderr_line(format_args!($($arg)*))
    };
}

pub mod behaviour;
pub mod builder;
pub mod console;
pub mod container;
pub mod inspect;
pub mod link;
pub mod module;
pub mod port;
pub mod resource;
pub mod service;
pub mod supervise;
mod sync;
#[cfg(any(test, feature = "test-support"))]
#[doc(hidden)]
pub mod test_support;
