//! Lockstep instants lost on the way: a Zenoh link that closes under load takes the
//! messages queued on it along while the session goes on over another link. The
//! receiver asks for them again and the run stays exact. The loss is made on purpose
//! (`lose_on_the_way`: the sender keeps the instant but never puts it), so the test
//! does not depend on the machine's load.

mod support;

use ferroc_zenoh::lockstep::lose_on_the_way;
use ferroc_zenoh::Keys;
use std::time::Duration;
use support::*;

/// Runs `a` and `b` of the echo application as two programs (one process each would
/// be the same) in lockstep for 6 cycles; every run must end cleanly.
fn run_pair(app: &str, tag: f64) {
    let registry = registry();
    let peers = two_peers();
    let start = |part: &str| {
        let options = over_zenoh(lockstep(6), app, part, &peers);
        echoes(&registry, &[part], tag).start_with(options).unwrap()
    };
    let (a, b) = (start("a"), start("b"));
    for app in [&a, &b] {
        assert!(
            app.wait_timeout(Duration::from_secs(30)),
            "the run did not end"
        );
        assert_eq!(app.failure(), None);
    }
}

#[test]
fn in_lockstep_instants_lost_on_the_way_are_sent_again_and_the_run_stays_exact() {
    let registry = registry();
    run_to_end(
        echoes(&registry, &["a", "b"], 20.0)
            .start_with(lockstep(6))
            .unwrap(),
    );
    let keys = Keys::new("lockstep_lost").unwrap();
    let a_to_b = keys.lockstep("a", "b").unwrap().to_string();
    let b_to_a = keys.lockstep("b", "a").unwrap().to_string();
    // The instants 0, 10, 20, 25, 30, 40 and 50 ms are #0 to #6 of each part. a's 10 ms
    // shows as a gap when its 20 ms comes; its 40 and 50 ms are its last ones, so b
    // hears nothing after them and asks once it has waited a while; b's 20 ms, a gap.
    for seq in [1, 5, 6] {
        lose_on_the_way(&a_to_b, seq);
    }
    lose_on_the_way(&b_to_a, 2);
    run_pair("lockstep_lost", 21.0);
    for (part, cycles) in [("a/", 6), ("b/", 3)] {
        assert_eq!(lines_of(21, part), lines_of(20, part), "{part}");
        assert_eq!(lines_of(21, part).len(), cycles, "{part}");
    }
    assert!(
        lines_of(21, "b/").iter().any(|l| l.ends_with("got 103")),
        "b heard a: {:?}",
        record(21)
    );
}
