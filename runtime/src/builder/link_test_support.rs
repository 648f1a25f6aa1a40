//! What the link and call-link tests share: a record of what modules saw (by a `tag`
//! parameter, since tests run in parallel), the two-part lockstep settings, addresses
//! on this computer, and waiting for a run to end.

use super::*;
use crate::link::net::Network;
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
pub(super) fn lockstep(cycles: u64, network: Option<Network>) -> StartOptions {
    StartOptions {
        limit: Some(cycles),
        lockstep: Some(Lockstep {
            periods: vec![Duration::from_millis(10), Duration::from_millis(25)],
            until: None,
        }),
        network,
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

/// A free address on 127.0.0.1.
pub(super) fn free_port() -> String {
    let l = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    l.local_addr().unwrap().to_string()
}

/// Parts `a` and `b` at free addresses.
pub(super) fn two_peers() -> BTreeMap<String, String> {
    [
        ("a".to_string(), free_port()),
        ("b".to_string(), free_port()),
    ]
    .into()
}

/// The network of `part` among `peers`, listening at its own address.
pub(super) fn network(part: &str, peers: &BTreeMap<String, String>) -> Option<Network> {
    Some(Network {
        part: part.into(),
        listen: peers[part].clone(),
        peers: peers.clone(),
    })
}
