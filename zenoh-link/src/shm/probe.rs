//! A computer without usable shared memory (no `/dev/shm`, a read-only one, as in some
//! containers): Zenoh refuses to open a session that asks for shared memory there
//! (`Unable to create POSIX shm segment`), so every session ferroc opens with it on —
//! a part's ([`crate::Zenoh`]) and the ROS 2 nodes' of `ferroc run`
//! ([`crate::ros2::network::Ros2Network`]) — is first checked here: where no small
//! segment can be made, the session opens without shared memory, after one warning.

use super::{Settings, ENABLED_KEY};
use ferroc_runtime::console;
use ferroc_terminal::engine_error;
use std::sync::atomic::{AtomicBool, Ordering};

/// Whose traffic takes the network instead, and where its configuration comes from:
/// the two things the warning names.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Whose {
    /// What travels over the network instead (plural).
    pub travels: &'static str,
    /// Where shared memory can be turned off to silence the warning.
    pub config: &'static str,
}

/// A part's links (its configuration from `--zenoh-config`).
pub(crate) const PARTS: Whose = Whose {
    travels: "links between parts on this computer",
    config: "--zenoh-config",
};

/// Turns shared memory off in `config` when this computer cannot give it, with one
/// warning for as long as `off` lives: the first session probes, sets `off` and
/// warns; later ones (a restarted part) take `off` as it is. A configuration with
/// shared memory off is left as it is.
pub(crate) fn off_where_unusable(
    config: &mut zenoh::Config,
    off: &AtomicBool,
    whose: Whose,
) -> Result<(), String> {
    let settings = Settings::of(config);
    if !settings.enabled {
        return Ok(());
    }
    if !off.load(Ordering::Relaxed) {
        let Some(cause) = unusable() else {
            return Ok(());
        };
        if !off.swap(true, Ordering::Relaxed) {
            warn_unusable(&cause, settings.pool_size, whose);
        }
    }
    config
        .insert_json5(ENABLED_KEY, "false")
        .map_err(|e| engine_error(&e))
}

/// The one warning where shared memory is not usable (`cause`, Zenoh's words), for a
/// pool of `pool_size` bytes.
pub(crate) fn warn_unusable(cause: &str, pool_size: usize, whose: Whose) {
    console::note(&format!(
        "warning: shared memory is not usable here ({cause}); {} travel over the \
         network. help: check that /dev/shm is mounted and has {} MiB free, or set \
         transport/shared_memory/enabled to false in {} to silence this",
        whose.travels,
        pool_size.div_ceil(1 << 20),
        whose.config
    ));
}

/// Why this computer cannot give shared memory at all, if it cannot: a small POSIX
/// segment cannot be made (no `/dev/shm`, or a read-only one).
#[cfg(feature = "shared-memory")]
fn unusable() -> Option<String> {
    super::Counting::provider(64 * 1024)
        .err()
        .map(|e| engine_error(&e))
}

/// Built without shared memory: nothing to make.
#[cfg(not(feature = "shared-memory"))]
fn unusable() -> Option<String> {
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn config(enabled: bool) -> zenoh::Config {
        let mut c = zenoh::Config::default();
        c.insert_json5(ENABLED_KEY, &enabled.to_string()).unwrap();
        c
    }

    fn enabled(c: &zenoh::Config) -> bool {
        Settings::of(c).enabled
    }

    /// Shared memory off by the configuration: nothing to probe, nothing said.
    #[test]
    fn a_configuration_without_shared_memory_is_left_as_it_is() {
        let (mut c, off) = (config(false), AtomicBool::new(false));
        off_where_unusable(&mut c, &off, PARTS).unwrap();
        assert!(!enabled(&c) && !off.load(Ordering::Relaxed));
    }

    /// This computer's /dev/shm works (the other shared-memory tests need it): the
    /// session keeps shared memory.
    #[test]
    fn where_shared_memory_works_the_session_keeps_it() {
        let (mut c, off) = (config(true), AtomicBool::new(false));
        off_where_unusable(&mut c, &off, PARTS).unwrap();
        assert!(enabled(&c) && !off.load(Ordering::Relaxed));
    }

    /// Once found unusable (and warned about), every later session of the same network
    /// opens without shared memory, without probing or warning again.
    #[test]
    fn once_found_unusable_later_sessions_open_without_it() {
        let (mut c, off) = (config(true), AtomicBool::new(true));
        off_where_unusable(&mut c, &off, PARTS).unwrap();
        assert!(!enabled(&c) && off.load(Ordering::Relaxed));
    }
}
