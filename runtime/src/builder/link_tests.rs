//! Links between parts: the same two-part application run in lockstep in one process
//! and as two "programs" (two builders) talking over TCP gives the same record, and
//! running freely values still arrive.

use super::link_test_support::*;
use super::tests::add;
use super::*;
use crate::link::{LinkSpec, Sharing};
use crate::module::{In, ModuleType, Out, Parameter};

/// Publishes `n · step + what it last received` and records what it saw when.
struct Echo {
    input: In<u32>,
    out: Out<u32>,
    step: Parameter<f64>,
    tag: Parameter<f64>,
    path: String,
    n: u32,
}
impl Module for Echo {
    fn update(&mut self) {
        self.n += 1;
        let got = self.input.get();
        let line = format!("{} @{}ms got {got}", self.path, model_ms());
        note(self.tag.get(), line);
        self.out.publish(self.n * self.step.get() as u32 + got);
    }
}
impl ModuleType for Echo {
    const NAME: &'static str = "test.Echo";
    fn create(m: &mut Setup<'_>) -> Self {
        Echo {
            input: m.input("in").build(),
            out: m.output("out").build(),
            step: m.param("step").default(1.0).build(),
            tag: m.param("tag").default(0.0).build(),
            path: m.path().to_owned(),
            n: 0,
        }
    }
}

const A_TO_B: LinkSpec<'static> = LinkSpec {
    id: 0,
    from_part: "a",
    to_part: "b",
    model_type: "u32",
    sharing: Sharing::OnChange {
        min_interval: Duration::ZERO,
    },
};
const B_TO_A: LinkSpec<'static> = LinkSpec {
    id: 1,
    from_part: "b",
    to_part: "a",
    model_type: "u32",
    sharing: Sharing::Periodic(Duration::from_millis(50)),
};

/// Part `a` (10 ms) and/or part `b` (25 ms), each end of each link in its own part.
fn build<'r>(registry: &'r Registry, parts: &[&str], tag: f64) -> Builder<'r> {
    let mut b = Builder::new(registry);
    let specs = [("a", 10, 1.0), ("b", 25, 100.0)];
    for &(part, ms, step) in specs.iter().filter(|(p, ..)| parts.contains(p)) {
        let path = format!("{part}/echo");
        let params = [
            ("step".into(), Value::Float(step)),
            ("tag".into(), Value::Float(tag)),
        ];
        add(&mut b, &path, "test.Echo", &params);
        b.add_thread(ThreadSpec {
            path: part.into(),
            schedule: Schedule::Periodic(Duration::from_millis(ms)),
            options: ThreadOptions::default(),
            steps: vec![(path, StepKind::Update)],
        })
        .unwrap();
    }
    for spec in [A_TO_B, B_TO_A] {
        let (from, to) = (
            format!("{}/echo", spec.from_part),
            format!("{}/echo", spec.to_part),
        );
        if parts.contains(&spec.from_part) {
            b.link_out(&spec, (&from, "out"), Conversion::default())
                .unwrap();
        }
        if parts.contains(&spec.to_part) {
            b.link_in(&spec, (&to, "in"), ConnectOptions::default())
                .unwrap();
        }
    }
    b
}

fn registry() -> Registry {
    let mut r = Registry::new();
    r.register::<Echo>();
    r
}

#[test]
fn in_lockstep_values_cross_at_the_next_instant_paced_by_their_sharing() {
    let registry = registry();
    let app = build(&registry, &["a", "b"], 1.0)
        .start_with(lockstep(8, None))
        .unwrap();
    run_to_end(app);
    // Eight cycles of the faster part: a runs at 0, 10, …, 70 ms and publishes n +
    // what it got; b runs at 0, 25, 50, 75 ms (the instants before 80 ms) and
    // publishes 100·n + what it got. Values reach the other part one instant later (b
    // sees a's 103 of 20 ms at 25 ms); b's link is periodic, 50 ms, so its 25 ms value
    // (303) is never sent and a keeps seeing the 100 sent at 0 ms until b's 50 ms value
    // (405) arrives at 60 ms.
    assert_eq!(
        record(1),
        [
            "a/echo @0ms got 0",
            "b/echo @0ms got 0",
            "a/echo @10ms got 100",
            "a/echo @20ms got 100",
            "b/echo @25ms got 103",
            "a/echo @30ms got 100",
            "a/echo @40ms got 100",
            "a/echo @50ms got 100",
            "b/echo @50ms got 105",
            "a/echo @60ms got 405",
            "a/echo @70ms got 405",
            "b/echo @75ms got 413",
        ]
    );
}

#[test]
#[cfg_attr(miri, ignore = "Miri has no sockets")]
fn two_programs_over_tcp_see_what_one_process_sees() {
    let registry = registry();
    run_to_end(
        build(&registry, &["a", "b"], 2.0)
            .start_with(lockstep(6, None))
            .unwrap(),
    );
    let peers = two_peers();
    let start = |part: &str| {
        let options = lockstep(6, network(part, &peers));
        build(&registry, &[part], 3.0).start_with(options).unwrap()
    };
    let (a, b) = (start("a"), start("b"));
    run_to_end(a);
    run_to_end(b);
    let split = |tag, part: &str| -> Vec<String> {
        record(tag)
            .into_iter()
            .filter(|l| l.starts_with(part))
            .collect()
    };
    // Six cycles of a (10 ms); b (25 ms) runs the instants before 60 ms: 0, 25, 50.
    for (part, cycles) in [("a/", 6), ("b/", 3)] {
        assert_eq!(split(3, part), split(2, part), "{part}");
        assert_eq!(split(3, part).len(), cycles);
    }
}

#[test]
fn running_freely_values_arrive_and_a_type_without_serde_is_refused() {
    let registry = registry();
    let app = build(&registry, &["a", "b"], 4.0).start(Some(40)).unwrap();
    run_to_end(app);
    let got_from_a = record(4)
        .iter()
        .filter(|l| l.starts_with("b/") && !l.ends_with("got 0"))
        .count();
    assert!(got_from_a > 0, "{:?}", record(4));

    let mut b = Builder::new(&registry);
    let mut spec = A_TO_B;
    spec.model_type = "no.SuchType";
    let err = b.link_in(&spec, ("b/echo", "in"), ConnectOptions::default());
    assert!(err.unwrap_err().to_string().contains("not registered"));
}

#[test]
fn a_link_to_a_part_without_an_address_is_refused_at_start() {
    let registry = registry();
    let err = build(&registry, &["a"], 5.0).start(Some(1)).err().unwrap();
    assert!(err.to_string().contains("no network addresses"), "{err}");
}

#[test]
#[cfg_attr(miri, ignore = "Miri has no sockets")]
fn running_freely_over_tcp_values_arrive_in_both_directions() {
    let registry = registry();
    let peers = two_peers();
    let start = |part: &str| {
        let options = StartOptions {
            limit: Some(60),
            lockstep: None,
            network: network(part, &peers),
        };
        build(&registry, &[part], 6.0).start_with(options).unwrap()
    };
    let (a, b) = (start("a"), start("b"));
    run_to_end(a);
    run_to_end(b);
    let heard = |part: &str| {
        record(6)
            .iter()
            .filter(|l| l.starts_with(part) && !l.ends_with("got 0"))
            .count()
    };
    assert!(heard("a/") > 0 && heard("b/") > 0, "{:?}", record(6));
}

#[test]
#[cfg_attr(miri, ignore = "Miri has no sockets")]
fn a_lockstep_part_waiting_for_a_missing_peer_still_stops_when_asked() {
    let registry = registry();
    let options = lockstep(1000, network("b", &two_peers()));
    // `a` never starts: `b` runs its first instant, then waits for `a`'s.
    let app = build(&registry, &["b"], 7.0).start_with(options).unwrap();
    std::thread::sleep(Duration::from_millis(200));
    assert!(!app.is_finished(), "it waits for the part `a`");
    app.stop();
    assert!(
        app.wait_timeout(Duration::from_secs(10)),
        "stopped while waiting"
    );
    assert_eq!(record(7), ["b/echo @0ms got 0"]);
}

#[test]
#[cfg_attr(miri, ignore = "Miri has no sockets")]
fn running_freely_a_sender_connects_again_after_its_peer_restarted() {
    let registry = registry();
    let peers = two_peers();
    let start = |part: &str, limit: u64, tag: f64| {
        let options = StartOptions {
            limit: Some(limit),
            lockstep: None,
            network: network(part, &peers),
        };
        build(&registry, &[part], tag).start_with(options).unwrap()
    };
    let a = start("a", 1000, 8.0);
    run_to_end(start("b", 20, 9.0));
    // `b` is gone; `a` notices when a write fails and connects to the new `b`.
    std::thread::sleep(Duration::from_millis(100));
    run_to_end(start("b", 40, 10.0));
    a.stop();
    run_to_end(a);
    let heard = |tag| record(tag).iter().filter(|l| !l.ends_with("got 0")).count();
    assert!(heard(9) > 0, "the first b heard a: {:?}", record(9));
    assert!(heard(10) > 0, "the second b heard a: {:?}", record(10));
}
