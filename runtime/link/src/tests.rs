use super::*;

fn at(ms: i64) -> Timestamp {
    Timestamp {
        nanos: ms * 1_000_000,
    }
}

#[test]
fn on_change_sends_news_at_most_once_per_interval_and_keeps_the_last() {
    let mut pace = Pace::new(Sharing::OnChange {
        min_interval: Duration::from_millis(100),
    });
    assert!(!pace.send(false, at(0)), "nothing published yet");
    assert!(pace.send(true, at(10)));
    assert!(!pace.send(true, at(50)), "within the interval");
    assert!(
        pace.send(false, at(110)),
        "the value held back goes out once it passed"
    );
    assert!(!pace.send(false, at(300)), "no news, nothing sent");
    let mut every = Pace::new(Sharing::default());
    assert!(every.send(true, at(0)) && every.send(true, at(0)) && !every.send(false, at(1)));
}

#[test]
fn a_link_that_sends_every_value_never_reads_the_clock() {
    let clock = |_: ()| -> Timestamp { panic!("the clock was read") };
    let mut every = Pace::new(Sharing::default());
    assert!(every.send_at(true, || clock(())));
    assert!(!every.send_at(false, || clock(())));
    // With an interval it does, and keeps the time of the last value sent.
    let mut paced = Pace::new(Sharing::OnChange {
        min_interval: Duration::from_millis(100),
    });
    assert!(paced.send_at(true, || at(10)));
    assert!(
        !paced.send_at(true, || at(100)),
        "within the interval from 10"
    );
    assert!(paced.send_at(false, || at(110)));
}

#[test]
fn periodic_sends_the_latest_value_every_period() {
    let mut pace = Pace::new(Sharing::Periodic(Duration::from_millis(50)));
    assert!(!pace.send(false, at(0)), "no value yet");
    assert!(pace.send(true, at(0)));
    assert!(!pace.send(false, at(25)));
    assert!(
        pace.send(false, at(50)),
        "again after a period, even without news"
    );
    assert!(pace.send(false, at(100)));
}

#[test]
fn a_value_that_does_not_decode_is_dropped_not_published() {
    let table = ferroc_module::ValueTable::default();
    let f64_type = table.get("f64").unwrap();
    let (out, handle) = f64_type.output("link 0 in");
    let (input, input_handle) = f64_type.input("reader", None);
    handle
        .connect(&input_handle, ferroc_ports::port::ConnectOptions::default())
        .unwrap();
    let codec = *f64_type.codec().unwrap();
    let inbox = Inbox::new(
        [(0, Receiving::new(out, codec, "test".into(), "a"))].into(),
        Default::default(),
    );
    inbox.deliver(&Frame {
        link: 0,
        bytes: vec![1, 2],
    });
    assert!(!input.changed(), "three bytes short of an f64");
    inbox.deliver(&Frame {
        link: 0,
        bytes: f64::INFINITY.to_le_bytes().to_vec(),
    });
    assert!(input.changed());
    assert_eq!(
        input.get_f64(),
        Some(f64::INFINITY),
        "infinity crosses exactly"
    );
    inbox.deliver(&Frame {
        link: 9,
        bytes: vec![],
    });
}

mod properties {
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

        /// Any bytes given to a link's receiving end are a value or a reported error.
        #[test]
        fn any_bytes_decode_without_panicking(bytes in proptest::collection::vec(any::<u8>(), 0..64)) {
            let table = ferroc_module::ValueTable::default();
            for name in table.names() {
                let value_type = table.get(name).unwrap();
                let (out, _) = value_type.output("link in");
                let _ = value_type.codec().unwrap().decode(&out, &bytes);
            }
        }
    }
}

#[test]
fn link_numbers_tell_data_requests_and_answers_apart() {
    use super::transport::{call_number, LinkKind};
    for kind in [
        LinkKind::Data(0),
        LinkKind::Data(7),
        LinkKind::Request(0),
        LinkKind::Answer(0),
        LinkKind::Request(3),
        LinkKind::Answer(3),
    ] {
        assert_eq!(LinkKind::of(kind.link()), kind);
    }
    assert_eq!(
        LinkKind::of(calls::CALL_LINKS - 1),
        LinkKind::Data(calls::CALL_LINKS - 1)
    );
    assert_eq!(call_number(&[5, 0, 0, 0, 0, 0, 0, 0, 9]), Some(5));
    assert_eq!(call_number(&[5, 0, 0]), None, "shorter than a number");
}
