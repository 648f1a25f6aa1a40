use super::net::{read_message, write_message, Message};
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
fn messages_round_trip_and_hostile_bytes_are_errors() {
    let messages = [
        Message::Hello("station".into()),
        Message::Frame(Frame {
            link: 7,
            bytes: vec![1, 2, 3],
        }),
        Message::Tick(25_000_000),
        Message::Bye,
    ];
    let mut bytes = Vec::new();
    for m in &messages {
        write_message(&mut bytes, m).unwrap();
    }
    let mut input = bytes.as_slice();
    for m in &messages {
        assert_eq!(read_message(&mut input).unwrap().as_ref(), Some(m));
    }
    assert_eq!(read_message(&mut input), Ok(None), "a clean end");
    let hostile: [&[u8]; 5] = [
        &[0, 0, 0, 0],                            // empty message
        &[255, 255, 255, 255],                    // 4 GiB announced
        &[2, 0, 0, 0, 9, 0],                      // unknown kind
        &[3, 0, 0, 0, 3, 1, 2],                   // a tick of 2 bytes
        &[5, 0, 0, 0, 1, 0xff, 0xfe, 0xfd, 0xfc], // a name that is not UTF-8
    ];
    for h in hostile {
        let mut input = h;
        assert!(read_message(&mut input).is_err(), "{h:?}");
    }
    let mut truncated: &[u8] = &[9, 0, 0, 0, 2, 1];
    assert!(read_message(&mut truncated).is_err());
}

#[test]
fn a_value_that_does_not_decode_is_dropped_not_published() {
    let table = crate::module::ValueTable::default();
    let f64_type = table.get("f64").unwrap();
    let (out, handle) = f64_type.output("link 0 in");
    let (input, input_handle) = f64_type.input("reader", None);
    handle
        .connect(&input_handle, crate::port::ConnectOptions::default())
        .unwrap();
    let wire = *f64_type.wire().unwrap();
    let inbox = Inbox::new(
        [(0, Receiving::new(out, wire, "test".into()))].into(),
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
    use super::*;
    use proptest::prelude::*;

    fn message() -> impl Strategy<Value = Message> {
        prop_oneof![
            "\\PC{0,40}".prop_map(Message::Hello),
            (any::<u32>(), proptest::collection::vec(any::<u8>(), 0..300))
                .prop_map(|(link, bytes)| Message::Frame(Frame { link, bytes })),
            any::<u64>().prop_map(Message::Tick),
            Just(Message::Bye),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

        /// Whatever bytes arrive, reading gives messages or an error, never a panic.
        #[test]
        fn any_bytes_read_without_panicking(bytes in proptest::collection::vec(any::<u8>(), 0..600)) {
            let mut input = bytes.as_slice();
            for _ in 0..64 {
                match read_message(&mut input) {
                    Ok(Some(_)) => {}
                    Ok(None) | Err(_) => break,
                }
            }
        }

        /// What is written reads back the same.
        #[test]
        fn messages_round_trip(messages in proptest::collection::vec(message(), 0..8)) {
            let mut bytes = Vec::new();
            for m in &messages {
                write_message(&mut bytes, m).unwrap();
            }
            let mut input = bytes.as_slice();
            for m in &messages {
                let got = read_message(&mut input).unwrap();
                prop_assert_eq!(got.as_ref(), Some(m));
            }
            prop_assert_eq!(read_message(&mut input), Ok(None));
        }

        /// Any bytes given to a link's receiving end are a value or a reported error.
        #[test]
        fn any_bytes_decode_without_panicking(bytes in proptest::collection::vec(any::<u8>(), 0..64)) {
            let table = crate::module::ValueTable::default();
            for name in table.names() {
                let value_type = table.get(name).unwrap();
                let (out, _) = value_type.output("link in");
                let _ = value_type.wire().unwrap().decode(&out, &bytes);
            }
        }
    }
}
