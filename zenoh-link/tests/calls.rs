//! Service calls between two part programs over Zenoh (a queryable in the service's
//! part, a `get` in the client's): in lockstep the answers come at the same instants
//! as in one process; running freely blocking calls are answered, and a call to a part
//! that is not there is an error value at once, not a hang.

mod support;

use std::time::{Duration, Instant};
use support::*;

#[test]
fn in_lockstep_two_programs_get_the_answers_one_process_gets() {
    let registry = registry();
    let one = callers(&registry, &["a", "b"], 102.0, false).start_with(lockstep(40));
    run_to_end(one.unwrap());
    let peers = two_peers();
    let start = |part: &str| {
        let options = over_zenoh(lockstep(40), "calls_lockstep", part, &peers);
        callers(&registry, &[part], 103.0, false)
            .start_with(options)
            .unwrap()
    };
    let (a, b) = (start("a"), start("b"));
    run_to_end(a);
    run_to_end(b);
    assert_eq!(record(103), record(102));
    assert!(
        record(102).iter().any(|l| l.contains("answer Ok(16)")),
        "{:?}",
        record(102)
    );
}

#[test]
fn running_freely_blocking_calls_are_answered_over_zenoh() {
    let registry = registry();
    let peers = two_peers();
    let b = callers(&registry, &["b"], 104.0, true)
        .start_with(over_zenoh(free(100_000), "calls_free", "b", &peers))
        .unwrap();
    let a = callers(&registry, &["a"], 104.0, true)
        .start_with(over_zenoh(free(100_000), "calls_free", "a", &peers))
        .unwrap();
    // Until the sessions found each other a call may fail; then they are answered.
    let answered = eventually(Duration::from_secs(20), || {
        record(104).iter().filter(|l| l.contains("Ok(")).count() >= 3
    });
    a.stop();
    b.stop();
    drop((a, b));
    assert!(answered, "{:?}", record(104));
    for line in record(104).iter().filter(|l| l.contains("Ok(")) {
        let (n, answer) = line.split_once(" → ").unwrap();
        let n: i64 = n.parse().unwrap();
        assert_eq!(answer, format!("Ok({})", n * n), "{line}");
    }
}

#[test]
fn a_call_to_a_part_that_is_not_there_is_an_error_at_once() {
    let registry = registry();
    let peers = two_peers();
    let started = Instant::now();
    // Only the client's part runs: no queryable answers, so the `get` ends at once.
    let a = callers(&registry, &["a"], 105.0, true)
        .start_with(over_zenoh(free(3), "calls_gone", "a", &peers))
        .unwrap();
    run_to_end(a);
    assert_eq!(
        record(105),
        [
            "1 → Err(Disconnected)",
            "2 → Err(Disconnected)",
            "3 → Err(Disconnected)"
        ]
    );
    // The client's own timeout is 5 s per call: far less than 3 × 5 s means no call
    // waited for it.
    assert!(
        started.elapsed() < Duration::from_secs(12),
        "{:?}",
        started.elapsed()
    );
}
