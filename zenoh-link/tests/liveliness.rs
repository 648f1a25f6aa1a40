//! Liveliness and staleness running freely: an input fed from another part is stale
//! until a value arrives, fresh while values come, stale again once the writer's part
//! is gone (its liveliness token withdrawn), and fresh when the part is back. Only
//! the order of these states is asserted, not how fast they change.

mod support;

use std::time::Duration;
use support::*;

/// The last state the probe of `tag` noted (`stale` or `fresh`).
fn state(tag: u64) -> String {
    let last = record(tag).last().cloned().unwrap_or_default();
    last.split(' ').next().unwrap_or_default().to_owned()
}

#[test]
fn an_input_from_a_part_that_is_gone_is_stale_and_fresh_again_when_it_is_back() {
    let registry = registry();
    let peers = two_peers();
    let start = |part: &str| {
        let options = over_zenoh(free(1_000_000), "alive", part, &peers);
        probed(&registry, part, 301.0).start_with(options).unwrap()
    };
    let wait = Duration::from_secs(20);
    let b = start("b");
    assert!(
        eventually(wait, || state(301) == "stale"),
        "{:?}",
        record(301)
    );
    assert!(
        record(301).iter().all(|l| l.ends_with("age none")),
        "nothing arrived, no age: {:?}",
        record(301)
    );
    let a = start("a");
    assert!(
        eventually(wait, || state(301) == "fresh"),
        "{:?}",
        record(301)
    );
    // `a` goes (as when killed: its session ends); the last value stays, stale.
    drop(a);
    assert!(
        eventually(wait, || state(301) == "stale"),
        "{:?}",
        record(301)
    );
    let last = record(301).last().cloned().unwrap();
    assert!(
        !last.contains("age none") && !last.starts_with("stale 0 "),
        "{last}"
    );
    // The status line and the log say so while it lasts, and since when.
    let gone_for = |status: &[String]| -> Option<f64> {
        let [line] = status else { return None };
        let rest = line.strip_prefix("link a → b: part a gone since ")?;
        rest.strip_suffix(" s")?.parse().ok()
    };
    let first = gone_for(&b.network_status());
    assert!(first.is_some(), "{:?}", b.network_status());
    assert!(
        eventually(wait, || gone_for(&b.network_status()) > first),
        "the time since goes on: {:?}",
        b.network_status()
    );
    let a = start("a");
    assert!(
        eventually(wait, || state(301) == "fresh"),
        "{:?}",
        record(301)
    );
    assert!(
        eventually(wait, || b.network_status().is_empty()),
        "back: {:?}",
        b.network_status()
    );
    a.stop();
    b.stop();
    drop((a, b));
}
