//! Zenoh's runtime threads in a part program: which of Zenoh's tokio runtimes runs
//! what. Zenoh reads them from the environment variable `ZENOH_RUNTIME` (RON), once,
//! when the program opens its first session, and from nowhere else.
//!
//! ferroc's default, [`DEFAULT`], hands Zenoh's acceptor runtime (`acc`) over to its
//! receive runtime (`rx`). A connection that a part *accepts* (the reader of a link
//! listens, its writer connects: [`super::connect`]) is made by the acceptor's task,
//! and tokio registers a socket with the runtime it was made in: every message that
//! arrived on it woke the acceptor's thread first (its `epoll_wait`), which then woke a
//! receive thread to read it; two thread wakeups a message instead of one
//! (`ferroc-bench b3-parts`: a consumer's CPU 81 → 62 µs a frame, bench/README.md).
//! The acceptor's own tasks (accepting, the handshake) are asynchronous and short; on
//! the receive runtime they wait at most while a link callback runs. The transmit
//! runtime (keep-alives) stays on its own thread.
//!
//! A `ZENOH_RUNTIME` in the environment wins whole (it is not merged with the
//! default): `ZENOH_RUNTIME='()'` gives Zenoh's own threads.

use std::ffi::OsString;

/// The environment variable Zenoh reads its runtime threads from.
pub const ENV: &str = "ZENOH_RUNTIME";

/// ferroc's runtime threads of a part program: the acceptor's tasks on the receive
/// runtime.
pub const DEFAULT: &str = "(acc: (handover: rx))";

/// The `ZENOH_RUNTIME` to set when the environment's value is `current`: ferroc's
/// [`DEFAULT`] when there is none, nothing when the user chose one (even an empty one).
pub fn to_set(current: Option<OsString>) -> Option<&'static str> {
    match current {
        Some(_) => None,
        None => Some(DEFAULT),
    }
}

/// Sets `ZENOH_RUNTIME` to ferroc's [`DEFAULT`] unless the environment names one;
/// what it set, if anything.
///
/// Call it first in `main`, before the program starts a thread (the environment is
/// not safe to write while another thread reads it) and before its first Zenoh
/// session (Zenoh reads the variable once). A generated bundle's part program calls
/// it when its part talks to others over Zenoh.
pub fn use_default() -> Option<&'static str> {
    let value = to_set(std::env::var_os(ENV))?;
    std::env::set_var(ENV, value);
    Some(value)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn without_a_setting_of_its_own_a_part_gets_the_acceptor_on_the_receive_runtime() {
        assert_eq!(to_set(None), Some("(acc: (handover: rx))"));
    }

    #[test]
    fn a_setting_in_the_environment_wins_even_an_empty_one() {
        assert_eq!(to_set(Some("(rx: (worker_threads: 1))".into())), None);
        assert_eq!(to_set(Some("()".into())), None);
        assert_eq!(to_set(Some("".into())), None);
    }
}
