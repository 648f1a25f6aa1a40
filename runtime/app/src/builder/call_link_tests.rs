//! Service calls between parts: a client in part `a` calls a service in part `b`, in
//! one process. In lockstep the answers come at exact instants; running freely,
//! blocking calls are answered; unregistered types are refused. (Two programs over the
//! network: `zenoh-link/tests/`.)

use super::tests::add;
use super::*;
use crate::test_support::*;

fn registry(with_call: bool) -> Registry {
    let mut r = Registry::new();
    r.register::<Asker>().register::<Squarer>();
    if with_call {
        r.register_call::<i64, i64>();
    }
    r
}

fn build<'r>(registry: &'r Registry, parts: &[&str], tag: f64, blocking: bool) -> Builder<'r> {
    let mut b = Builder::new(registry);
    if parts.contains(&"a") {
        let params = [
            ("tag".to_string(), Value::Float(tag)),
            ("blocking".to_string(), Value::Bool(blocking)),
        ];
        add(&mut b, "a/asker", "test.Asker", &params);
        b.call_out(&CALL, ("a/asker", "ask")).unwrap();
        b.add_thread(ThreadSpec {
            path: "a".into(),
            schedule: Schedule::Periodic(Duration::from_millis(10)),
            options: ThreadOptions::default(),
            steps: vec![("a/asker".into(), StepKind::Update)],
        })
        .unwrap();
    }
    if parts.contains(&"b") {
        add(&mut b, "b/squarer", "test.Squarer", &[]);
        b.call_in(&CALL, ("b/squarer", "square")).unwrap();
        b.add_thread(ThreadSpec {
            path: "b".into(),
            schedule: Schedule::Periodic(Duration::from_millis(25)),
            options: ThreadOptions::default(),
            steps: vec![("b/squarer".into(), StepKind::Update)],
        })
        .unwrap();
    }
    b
}

#[test]
fn in_lockstep_a_call_is_answered_two_instants_and_a_server_cycle_later() {
    let registry = registry(true);
    let app = build(&registry, &["a", "b"], 101.0, false).start_with(lockstep(6));
    run_to_end(app.unwrap());
    // Asked at 0 ms; the request reaches b at 10 ms, b serves it at 25 ms, the answer
    // reaches a at 30 ms.
    assert_eq!(
        record(101),
        [
            "a @0ms waits, asks 1",
            "a @10ms waits",
            "a @20ms waits",
            "a @30ms answer Ok(1), asks 2",
            "a @40ms waits",
            "a @50ms waits",
        ]
    );
}

#[test]
fn running_freely_blocking_calls_between_parts_are_answered() {
    let registry = registry(true);
    let app = build(&registry, &["a", "b"], 104.0, true)
        .start(Some(5))
        .unwrap();
    run_to_end(app);
    assert_eq!(
        record(104),
        [
            "1 → Ok(1)",
            "2 → Ok(4)",
            "3 → Ok(9)",
            "4 → Ok(16)",
            "5 → Ok(25)"
        ]
    );
}

#[test]
fn calls_of_unregistered_types_cannot_cross() {
    let registry = registry(false);
    let mut b = Builder::new(&registry);
    add(&mut b, "a/asker", "test.Asker", &[]);
    let err = b
        .call_out(&CALL, ("a/asker", "ask"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("register_call::<i64, i64>()"), "{err}");
}
