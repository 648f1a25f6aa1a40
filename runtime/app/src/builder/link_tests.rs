//! Links between parts in one process: in lockstep values cross at the next instant,
//! paced by their sharing; running freely they arrive; a link leaving the process
//! without a network is refused. (Two programs over the network: `zenoh-link/tests/`.)

use super::tests::add;
use super::*;
use crate::test_support::*;
use ferroc_link::LinkSpec;
use ferroc_ports::port::ConnectOptions;

/// Part `a` (10 ms) and/or part `b` (25 ms), each end of each link in its own part.
fn build<'r>(registry: &'r Registry, parts: &[&str], tag: f64) -> Builder<'r> {
    build_with(registry, parts, tag, [A_TO_B, B_TO_A])
}

/// [`build`] with other link specs.
fn build_with<'r>(
    registry: &'r Registry,
    parts: &[&str],
    tag: f64,
    links: [LinkSpec<'static>; 2],
) -> Builder<'r> {
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
    for spec in links {
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
        .start_with(lockstep(8))
        .unwrap();
    run_to_end(app);
    // Eight cycles of the faster part: a runs at 0, 10, …, 70 ms and publishes n +
    // what it got; b runs at 0, 25, 50, 75 ms (the instants before 80 ms) and
    // publishes 100·n + what it got. Values reach the other part one instant later (b
    // sees a's 103 of 20 ms at 25 ms); b's link is periodic, 50 ms, so its 25 ms value
    // (303) is never sent and a keeps seeing the 100 sent at 0 ms until b's 50 ms value
    // (405) arrives at 60 ms. At 0 ms nothing has arrived yet: both inputs are stale,
    // their zeros are not data.
    assert_eq!(
        record(1),
        [
            "a/echo @0ms got 0 (stale)",
            "b/echo @0ms got 0 (stale)",
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
fn past_its_deadline_a_links_input_is_stale_until_the_next_value() {
    let registry = registry();
    let mut b_to_a = B_TO_A;
    b_to_a.deadline = Some(Duration::from_millis(30));
    let app = build_with(&registry, &["a", "b"], 11.0, [A_TO_B, b_to_a])
        .start_with(lockstep(7))
        .unwrap();
    run_to_end(app);
    // b's periodic (50 ms) values reach a at 10 and 60 ms; a runs every 10 ms.
    let stale: Vec<(String, bool)> = record(11)
        .iter()
        .filter(|l| l.starts_with("a/"))
        .map(|l| {
            let at = l.split(' ').nth(1).unwrap_or_default().to_owned();
            (at, l.ends_with("(stale)"))
        })
        .collect();
    let expected = [
        ("@0ms", true),   // nothing yet
        ("@10ms", false), // arrived now
        ("@20ms", false),
        ("@30ms", false),
        ("@40ms", false), // 30 ms old: exactly the deadline
        ("@50ms", true),  // 40 ms old
        ("@60ms", false), // the next value
    ];
    let expected: Vec<(String, bool)> = expected.iter().map(|(a, s)| (a.to_string(), *s)).collect();
    assert_eq!(stale, expected);
}

#[test]
fn running_freely_values_arrive_and_a_type_without_serde_is_refused() {
    let registry = registry();
    let app = build(&registry, &["a", "b"], 4.0).start(Some(40)).unwrap();
    run_to_end(app);
    let got_from_a = record(4)
        .iter()
        .filter(|l| l.starts_with("b/") && !l.contains("got 0"))
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
    assert!(
        err.to_string().contains("no network to other parts"),
        "{err}"
    );
}

/// A network that records which links each encoded value was sent on.
#[derive(Default)]
struct Recording(Arc<std::sync::Mutex<Vec<Vec<u32>>>>);

impl ferroc_link::transport::Network for Recording {
    fn open(
        &self,
        _links: &ferroc_link::transport::PartLinks,
        _delivery: ferroc_link::transport::Delivery,
        _lockstep: bool,
    ) -> Result<Box<dyn ferroc_link::transport::Connection>, String> {
        Ok(Box::new(Recording(Arc::clone(&self.0))))
    }
}

impl ferroc_link::transport::Connection for Recording {
    fn send(&self, _to_part: &str, frame: ferroc_link::Frame) {
        self.0.lock().unwrap().push(vec![frame.link]);
    }
    fn send_encoded(
        &self,
        targets: &[(u32, Arc<str>)],
        encoder: &ferroc_module::Encoder<'_>,
    ) -> Result<(), String> {
        encoder.to_vec()?;
        let links = targets.iter().map(|(link, _)| *link).collect();
        self.0.lock().unwrap().push(links);
        Ok(())
    }
    fn end_instant(
        &self,
        _nanos: u64,
        _frames: Vec<(Arc<str>, ferroc_link::Frame)>,
        _stop: &std::sync::atomic::AtomicBool,
    ) -> Result<(), String> {
        Ok(())
    }
    fn wait_instant(
        &self,
        _nanos: u64,
        _stop: &std::sync::atomic::AtomicBool,
    ) -> Result<Vec<ferroc_link::Frame>, String> {
        Ok(Vec::new())
    }
    fn close(&self) {}
}

/// Links that carry one output's values unchanged to several parts are encoded and
/// sent once for all of them; a link that differs (here its sharing) goes on its own.
#[test]
fn links_of_one_output_to_several_parts_are_sent_once_for_all() {
    let registry = registry();
    let mut b = Builder::new(&registry);
    add(&mut b, "a/echo", "test.Echo", &[]);
    b.add_thread(ThreadSpec {
        path: "a".into(),
        schedule: Schedule::Periodic(Duration::from_millis(2)),
        options: ThreadOptions::default(),
        steps: vec![("a/echo".into(), StepKind::Update)],
    })
    .unwrap();
    let to = |id, to_part| LinkSpec {
        id,
        to_part,
        ..A_TO_B
    };
    let periodic = LinkSpec {
        sharing: ferroc_link::Sharing::Periodic(Duration::from_millis(4)),
        ..to(2, "d")
    };
    for spec in [to(0, "b"), to(1, "c"), periodic] {
        b.link_out(&spec, ("a/echo", "out"), Conversion::default())
            .unwrap();
    }
    let sent = Recording::default();
    let log = Arc::clone(&sent.0);
    let options = StartOptions {
        network: Some(Arc::new(sent)),
        ..StartOptions::default()
    };
    let app = b.start_with(options).unwrap();
    let enough = || {
        let log = log.lock().unwrap();
        log.iter().filter(|l| l.len() == 2).count() >= 3 && log.contains(&vec![2])
    };
    let limit = std::time::Instant::now() + Duration::from_secs(30);
    while !enough() && std::time::Instant::now() < limit {
        std::thread::sleep(Duration::from_millis(10));
    }
    let enough = enough();
    app.stop();
    let log = log.lock().unwrap();
    assert!(enough, "{log:?}");
    assert!(
        log.iter().all(|l| *l == [0, 1] || *l == [2]),
        "sent otherwise: {log:?}"
    );
}
