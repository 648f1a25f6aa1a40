//! The bottom of ferroc's runtime: data ports and services, and the little they need
//! from around them (timestamps, the freshness of linked inputs, the application's stop
//! flag, thread placement, console output). Depends on nothing else of ferroc's.
//!
//! * [`port`] — output and input ports, buffer pools, n:m connections, input queues,
//!   data-triggered wakeups. Publishing is lock-free and zero-copy; connections change
//!   at run time without blocking publishers.
//! * [`service`] — request/response ports: a service executed by the serving module's
//!   thread container (or inline by its callers), blocking and asynchronous clients
//!   with optional timeouts; every failure is an error value, never a hang.
//! * [`time`] — [`Timestamp`](time::Timestamp), the port value of the model type
//!   `timestamp`, and the model time of lockstep runs.
//! * [`fresh`] — how fresh the values of a link between parts are, as the inputs it
//!   feeds see them.
//! * [`stopping`] — the stop flag that waits inside the port core give up on.
//! * [`thread`] — real-time priority and CPU affinity of the calling thread.
//! * [`console`] — warnings and module output that keep the live status line intact.
//!
//! This is the one runtime crate with `unsafe` (the port core's lock-free structures
//! and the two system calls of [`thread`]); every block has a `SAFETY:` comment. Its
//! concurrency is verified with loom (`RUSTFLAGS="--cfg loom" cargo test -p ferroc-ports
//! --release --test loom_ports --test loom_services --test loom_wakeup --test
//! loom_local`) and Miri (`cargo +nightly miri test -p ferroc-ports --lib port::`);
//! `runtime/verify.sh` runs both.

#![warn(missing_docs)]

/// `eprintln!` that does not panic when standard error is closed or full (see
/// [`console::stderr_line`]); it shadows std's in this whole crate. Every runtime crate
/// that prints defines the same shadow at its root.
#[allow(unused_macros)] // no print here today; kept so that none ever uses std's
macro_rules! eprintln {
    ($($arg:tt)*) => {
        $crate::console::stderr_line(format_args!($($arg)*))
    };
}

pub mod console;
pub mod fresh;
pub mod port;
pub mod service;
pub mod stopping;
#[doc(hidden)]
pub mod sync;
pub mod thread;
pub mod time;
