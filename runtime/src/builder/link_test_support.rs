//! What the link and call-link tests share: a record of what modules saw (by a `tag`
//! parameter, since tests run in parallel), the two-part lockstep settings, and
//! waiting for a run to end.

use super::*;
use crate::module::Timestamp;
use std::collections::BTreeMap;
use std::sync::Mutex;

/// What each module saw, by its `tag` (each test uses its own).
static RECORD: Mutex<BTreeMap<u64, Vec<String>>> = Mutex::new(BTreeMap::new());

/// Adds a line to the record of `tag`.
pub(super) fn note(tag: f64, line: String) {
    RECORD
        .lock()
        .unwrap()
        .entry(tag as u64)
        .or_default()
        .push(line);
}

/// Everything noted under `tag`, in order.
pub(super) fn record(tag: u64) -> Vec<String> {
    RECORD
        .lock()
        .unwrap()
        .get(&tag)
        .cloned()
        .unwrap_or_default()
}

/// Milliseconds of model time (in lockstep) since the start.
pub(super) fn model_ms() -> i64 {
    (Timestamp::now().nanos - Timestamp::LOCKSTEP_EPOCH.nanos) / 1_000_000
}

/// Lockstep for parts `a` (10 ms) and `b` (25 ms), each container `cycles` cycles.
pub(super) fn lockstep(cycles: u64) -> StartOptions {
    StartOptions {
        limit: Some(cycles),
        lockstep: Some(Lockstep {
            periods: vec![Duration::from_millis(10), Duration::from_millis(25)],
            until: None,
        }),
        network: None,
    }
}

/// Waits (at most 20 s) until the run ends, then stops it.
pub(super) fn run_to_end(app: RunningApp) {
    assert!(
        app.wait_timeout(Duration::from_secs(20)),
        "the run did not end"
    );
    drop(app);
}
