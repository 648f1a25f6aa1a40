//! Links between two part programs over Zenoh (two builders, two sessions, on
//! 127.0.0.1): in lockstep they see exactly what one process sees; running freely
//! values arrive both ways and again after a part restarted.

mod support;

use std::time::Duration;
use support::*;

#[test]
fn in_lockstep_two_programs_see_what_one_process_sees() {
    let registry = registry();
    run_to_end(
        echoes(&registry, &["a", "b"], 2.0)
            .start_with(lockstep(6))
            .unwrap(),
    );
    let peers = two_peers();
    let start = |part: &str| {
        let options = over_zenoh(lockstep(6), "links_lockstep", part, &peers);
        echoes(&registry, &[part], 3.0).start_with(options).unwrap()
    };
    let (a, b) = (start("a"), start("b"));
    for app in [&a, &b] {
        assert!(
            app.wait_timeout(Duration::from_secs(30)),
            "the run did not end"
        );
        assert_eq!(app.failure(), None);
    }
    drop((a, b));
    // Six cycles of a (10 ms); b (25 ms) runs the instants before 60 ms: 0, 25, 50.
    for (part, cycles) in [("a/", 6), ("b/", 3)] {
        assert_eq!(lines_of(3, part), lines_of(2, part), "{part}");
        assert_eq!(lines_of(3, part).len(), cycles, "{part}");
    }
    assert!(
        lines_of(3, "b/").iter().any(|l| l.ends_with("got 103")),
        "b heard a: {:?}",
        record(3)
    );
}

#[test]
fn running_freely_values_arrive_in_both_directions() {
    let registry = registry();
    let peers = two_peers();
    let start = |part: &str| {
        let options = over_zenoh(free(1000), "links_free", part, &peers);
        echoes(&registry, &[part], 6.0).start_with(options).unwrap()
    };
    let (a, b) = (start("a"), start("b"));
    let heard = |part: &str| {
        lines_of(6, part)
            .iter()
            .filter(|l| !l.ends_with("got 0") && !l.ends_with("(stale)"))
            .count()
    };
    let both = eventually(Duration::from_secs(20), || {
        heard("a/") > 0 && heard("b/") > 0
    });
    a.stop();
    b.stop();
    drop((a, b));
    assert!(both, "{:?}", record(6));
}

#[test]
fn running_freely_values_arrive_again_after_the_reader_restarted() {
    let registry = registry();
    let peers = two_peers();
    let start = |part: &str, tag: f64| {
        let options = over_zenoh(free(100_000), "links_restart", part, &peers);
        echoes(&registry, &[part], tag).start_with(options).unwrap()
    };
    let heard = |tag| {
        lines_of(tag, "b/")
            .iter()
            .filter(|l| !l.ends_with("got 0") && !l.ends_with("(stale)"))
            .count()
    };
    let a = start("a", 8.0);
    let b = start("b", 9.0);
    assert!(
        eventually(Duration::from_secs(20), || heard(9) > 0),
        "{:?}",
        record(9)
    );
    b.stop();
    drop(b);
    // `b` is gone; a new `b` on the same address hears `a` again.
    let b = start("b", 10.0);
    let again = eventually(Duration::from_secs(20), || heard(10) > 0);
    a.stop();
    b.stop();
    drop((a, b));
    assert!(again, "the second b heard a: {:?}", record(10));
}

#[test]
fn a_lockstep_part_waiting_for_a_missing_peer_still_stops_when_asked() {
    let registry = registry();
    let options = over_zenoh(lockstep(1000), "links_missing", "b", &two_peers());
    // `a` never starts: `b` waits for it to listen before sending its first instant.
    let app = echoes(&registry, &["b"], 7.0).start_with(options).unwrap();
    std::thread::sleep(Duration::from_millis(300));
    assert!(!app.is_finished(), "it waits for the part `a`");
    app.stop();
    assert!(
        app.wait_timeout(Duration::from_secs(10)),
        "stopped while waiting"
    );
    assert_eq!(app.failure(), None, "asked to stop is not a failure");
    assert_eq!(record(7), ["b/echo @0ms got 0 (stale)"]);
}

#[test]
fn an_address_in_use_is_an_error_naming_the_option() {
    let registry = registry();
    let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let mut peers = two_peers();
    peers.insert("b".into(), taken.local_addr().unwrap().to_string());
    let options = over_zenoh(free(10), "links_in_use", "b", &peers);
    let err = echoes(&registry, &["b"], 11.0)
        .start_with(options)
        .err()
        .unwrap()
        .to_string();
    assert!(
        err.contains("--listen") && err.contains("cannot listen"),
        "{err}"
    );
}

#[test]
fn in_lockstep_a_peer_that_stops_ends_the_run_with_an_error_naming_it() {
    let registry = registry();
    let peers = two_peers();
    let start = |part: &str| {
        let options = over_zenoh(lockstep(1_000_000), "links_dies", part, &peers);
        echoes(&registry, &[part], 12.0)
            .start_with(options)
            .unwrap()
    };
    let (a, b) = (start("a"), start("b"));
    assert!(
        eventually(Duration::from_secs(20), || lines_of(12, "b/").len() > 10),
        "the parts run in step: {:?}",
        record(12).len()
    );
    // `a` goes away (as when killed: its session ends); `b` waits for `a`'s next
    // instant, learns through liveliness that it is gone and fails.
    drop(a);
    assert!(
        b.wait_timeout(Duration::from_secs(20)),
        "b did not end: a hang"
    );
    let failure = b.failure().unwrap_or_default().to_owned();
    assert!(failure.contains("the part `a` is gone"), "{failure}");
    assert_eq!(b.end_reason(), "failed");
}

#[test]
fn in_lockstep_a_part_that_only_sends_ends_with_an_error_when_its_reader_is_gone() {
    let registry = registry();
    let peers = two_peers();
    let start = |part: &str, cycles: u64| {
        let options = over_zenoh(lockstep(cycles), "links_sender", part, &peers);
        probed(&registry, part, 14.0).start_with(options).unwrap()
    };
    let (a, b) = (start("a", 100_000_000), start("b", 100_000_000));
    assert!(
        eventually(Duration::from_secs(20), || probe_lines(14) > 10),
        "the reader runs: {:?}",
        record(14)
    );
    // `a` waits for nobody; once `b` is gone its instants go nowhere, so it must stop.
    drop(b);
    assert!(
        a.wait_timeout(Duration::from_secs(30)),
        "a runs on alone, as if all were well"
    );
    let failure = a.failure().unwrap_or_default().to_owned();
    assert!(
        failure.contains("the part `b` is gone") && failure.contains("no longer receives"),
        "{failure}"
    );
    assert_eq!(a.end_reason(), "failed");
}

#[test]
fn in_lockstep_a_part_that_only_sends_ends_cleanly_when_both_reach_the_limit() {
    let registry = registry();
    let peers = two_peers();
    let start = |part: &str| {
        let options = over_zenoh(lockstep(40), "links_sender_end", part, &peers);
        probed(&registry, part, 15.0).start_with(options).unwrap()
    };
    let (a, b) = (start("a"), start("b"));
    for app in [&a, &b] {
        assert!(app.wait_timeout(Duration::from_secs(30)), "the run ends");
        assert_eq!(app.failure(), None);
    }
    assert_eq!(
        probe_lines(15),
        16,
        "b's instants before 400 ms: {:?}",
        record(15)
    );
    drop((a, b));
}

/// How many cycles the probe of `b` noted under `tag` (`a`'s echo notes its own).
fn probe_lines(tag: u64) -> usize {
    record(tag).iter().filter(|l| !l.starts_with("a/")).count()
}
