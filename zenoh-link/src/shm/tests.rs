use super::*;
use zenoh::shm::ZShm;

fn settings(pool_size: usize) -> Settings {
    Settings {
        enabled: true,
        threshold: 4096,
        pool_size,
    }
}

#[test]
fn large_values_go_into_the_pool_and_small_ones_do_not() {
    let pool = Pool::open(settings(1 << 20));
    assert!(pool.usage().active, "this machine has /dev/shm");
    assert_eq!(pool.room_for(200_000), Some(5), "1 MiB holds five");
    let big = vec![7u8; 10_000];
    match pool.payload(big.clone(), true, "link") {
        Payload::Shared(z) => {
            assert!(z.as_shm().is_some());
            assert_eq!(z.to_bytes().as_ref(), big.as_slice());
        }
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        pool.payload(vec![1; 4095], true, "link"),
        Payload::Network(_)
    ));
    assert_eq!(pool.usage().shared, 1);
}

#[test]
fn a_buffer_comes_back_only_when_nobody_holds_it() {
    let pool = Pool::open(settings(64 * 1024));
    let held = pool.payload(vec![1; 40_000], false, "link");
    assert!(matches!(held, Payload::Shared(_)));
    // The pool cannot hold a second one while the first is held: drop policy drops.
    assert!(matches!(
        pool.payload(vec![2; 40_000], false, "link"),
        Payload::Dropped
    ));
    assert_eq!(pool.usage().dropped, 1);
    assert_eq!(pool.room_for(40_000), Some(0));
    drop(held);
    assert_eq!(pool.room_for(40_000), Some(1));
    assert!(matches!(
        pool.payload(vec![3; 40_000], false, "link"),
        Payload::Shared(_)
    ));
}

/// A value decoded in place from a pool buffer holds it: the pool cannot hand the
/// buffer out again (nobody writes it) until the value is dropped.
#[test]
fn a_buffer_a_decoded_value_reads_in_place_is_not_reused_while_it_lives() {
    use ferroc_runtime::module::bytes::{decode_in_place, Holder};
    use ferroc_runtime::module::{Bytes, Encoder};
    use std::sync::Arc;
    let pool = Pool::open(settings(64 * 1024));
    let value: (u32, Bytes) = (7, vec![3; 40_000].into());
    let len = postcard::experimental::serialized_size(&value).unwrap();
    let write =
        |buf: &mut [u8]| (postcard::to_slice(&value, buf).map(|_| ())).map_err(|e| e.to_string());
    let payload = pool.payload_encoded(&Encoder::new(len, &write), false, "link");
    let Ok(Payload::Shared(zbytes)) = payload else {
        panic!("{payload:?}");
    };
    let holder: Arc<dyn Holder> = Arc::new(zbytes.as_shm().unwrap().to_owned());
    drop(zbytes);
    let decoded: (u32, Bytes) = decode_in_place(&holder, |b| postcard::from_bytes(b)).unwrap();
    drop(holder);
    assert!(decoded.1.is_shared());
    assert_eq!(decoded, value);
    assert_eq!(pool.room_for(40_000), Some(0), "the value still reads it");
    drop(decoded);
    assert_eq!(
        pool.room_for(40_000),
        Some(1),
        "back once the value is gone"
    );
    // A value the encoder says is larger than its buffer is an error, not a panic.
    let short = Encoder::new(40_000, &write);
    assert!(pool.payload_encoded(&short, false, "link").is_err());
}

/// A lent buffer is written only while nobody else holds it: once handed to Zenoh
/// (or held by a reader) a write would copy it first (`Bytes`); it is writable
/// again only when everybody let it go.
#[test]
fn a_lent_buffer_is_written_only_while_nobody_else_holds_it() {
    let pool = Pool::open(settings(1 << 20));
    assert!(
        pool.lend(100).is_none(),
        "below the threshold: plain memory"
    );
    assert!(
        pool.lend(2 << 20).is_none(),
        "larger than the pool: plain memory"
    );
    let mut lent = pool.lend(200_000).expect("room");
    lent.bytes_mut().expect("nobody else holds it").fill(7);
    let sent = lent.as_any().downcast_ref::<Lent>().unwrap().shared();
    assert!(lent.bytes_mut().is_none(), "sent: no more writes");
    assert!(sent.to_bytes().iter().all(|b| *b == 7));
    assert_eq!(pool.room_for(200_000), Some(4), "it stays taken");
    drop(sent);
    assert!(lent.bytes_mut().is_some(), "let go: writable again");
    drop(lent);
    assert_eq!(pool.room_for(200_000), Some(5), "back in the pool");
    // A full pool lends nothing (the output then lends plain memory), never waits.
    let held: Vec<_> = (0..5).filter_map(|_| pool.lend(200_000)).collect();
    assert_eq!(held.len(), 5);
    assert!(pool.lend(200_000).is_none());
}

#[test]
fn a_reliable_link_on_a_full_pool_waits_then_takes_the_network() {
    let pool = Pool::open(settings(64 * 1024));
    let _held = pool.payload(vec![1; 40_000], true, "link");
    let sent = pool.payload(vec![2; 40_000], true, "link");
    match sent {
        Payload::Network(z) => assert_eq!(z.len(), 40_000),
        other => panic!("{other:?}"),
    }
    let used = pool.usage();
    assert_eq!((used.shared, used.network, used.dropped), (1, 1, 0));
}

#[test]
fn without_shared_memory_everything_takes_the_network() {
    let off = Pool::open(Settings {
        enabled: false,
        ..settings(1 << 20)
    });
    assert!(!off.usage().active);
    assert!(matches!(
        off.payload(vec![1; 100_000], true, "link"),
        Payload::Network(_)
    ));
    // A pool the system cannot provide (larger than any /dev/shm): one warning, then
    // the network path.
    let impossible = Pool::open(settings(1 << 62));
    assert!(!impossible.usage().active);
    assert!(matches!(
        impossible.payload(vec![1; 100_000], true, "link"),
        Payload::Network(_)
    ));
}

#[test]
fn the_settings_are_read_from_the_configuration() {
    let mut c = zenoh::Config::default();
    c.insert_json5(THRESHOLD_KEY, "10000").unwrap();
    let s = Settings::of(&c);
    assert_eq!(s.threshold, 10000);
    assert!(s.enabled, "Zenoh's default");
    c.insert_json5(ENABLED_KEY, "false").unwrap();
    assert!(!Settings::of(&c).enabled);
}

/// A value sent in a 40 000-byte buffer of `pool` while the sessions `peers` were
/// there, one of them still holding it (as a reader does: its own count); returns
/// that reader's reference.
fn sent_and_held(pool: &Pool, peers: &[&str]) -> ZShm {
    let provider = pool.provider.as_ref().unwrap();
    let now = std::time::Instant::now();
    for peer in peers {
        provider.ledger.transport(peer.to_string(), true, now);
    }
    let payload = pool.payload(vec![9; 40_000], false, "link");
    let Payload::Shared(bytes) = &payload else {
        panic!("{payload:?}");
    };
    let reader = bytes.as_shm().unwrap().to_owned();
    pool.sent(&Pool::addresses(&payload), None);
    reader
}

/// [`sent_and_held`], the put stamped `send` (publisher, number: asking.rs).
fn sent_stamped(pool: &Pool, peers: &[&str], send: (u32, u32)) -> ZShm {
    let provider = pool.provider.as_ref().unwrap();
    let now = std::time::Instant::now();
    for peer in peers {
        provider.ledger.transport(peer.to_string(), true, now);
    }
    let payload = pool.payload(vec![8; 40_000], false, "link");
    let Payload::Shared(bytes) = &payload else {
        panic!("{payload:?}");
    };
    let reader = bytes.as_shm().unwrap().to_owned();
    pool.sent(&Pool::addresses(&payload), Some(send));
    reader
}

/// A reader's answer: it has seen publisher 7 up to `last` and holds `held`.
fn answer(reader: &str, last: u32, held: &[u32]) -> asking::Answer {
    asking::Answer {
        reader: reader.to_owned(),
        receives: true,
        publishers: vec![asking::Seen {
            publisher: 7,
            last,
            held: held.to_vec(),
        }],
    }
}

/// Several readers were sent one buffer, one of them was killed holding it: it comes
/// back once every live one answered that it has seen it go by and holds it no more,
/// and not before (one not asked yet, one that has not seen it yet, one that still
/// holds it, an answer to an older session's question).
#[test]
fn a_buffer_a_killed_reader_shares_comes_back_once_the_live_ones_let_go() {
    let pool = Pool::open(settings(64 * 1024));
    let ledger = &pool.provider.as_ref().unwrap().ledger;
    ledger.attach();
    let (killed, one, two) = (dead(), process::session_id(), process::session_id());
    let held_by_killed = sent_stamped(&pool, &[&killed, &one, &two], (7, 41));
    gone(&pool, &killed);
    assert_eq!(pool.usage().gone_held, 1);
    let now = std::time::Instant::now();
    let asked = ledger
        .to_ask(now)
        .expect("a buffer waits for the live readers");
    assert_eq!(ledger.to_ask(now), None, "one question at a time");
    ledger.answered(asked, &answer(&one, 41, &[]));
    assert_eq!(reclaim_later(&pool, GRACE * 100), 0, "two has not answered");
    ledger.answered(asked, &answer(&two, 40, &[]));
    assert_eq!(
        reclaim_later(&pool, GRACE * 100),
        0,
        "two has not seen it yet"
    );
    ledger.answered(asked, &answer(&two, 45, &[41]));
    assert_eq!(reclaim_later(&pool, GRACE * 100), 0, "two still holds it");
    ledger.answered(asked + 1, &answer(&two, 45, &[]));
    assert_eq!(
        reclaim_later(&pool, GRACE * 100),
        0,
        "another session's question"
    );
    ledger.answered(asked, &answer(&two, 45, &[44]));
    // The grace runs from when the last one let go.
    assert_eq!(reclaim_later(&pool, GRACE / 2), 0, "within the grace");
    assert_eq!(reclaim_later(&pool, GRACE * 2), 1);
    assert_eq!(pool.usage().reclaimed, 1);
    assert_eq!(pool.usage().gone_held, 0);
    assert_eq!(pool.room_for(40_000), Some(1), "back, though still counted");
    ledger.asked();
    let later = now + asking::ASK_EVERY;
    assert_eq!(ledger.to_ask(later), None, "nothing waits any more");
    drop(held_by_killed);
}

/// The silent side: a buffer also sent to a session that never answers (a Python
/// client, bare Zenoh) stays, whatever the others answer; a part that does not
/// receive from the writer is done with everything; a reader that answers for a buffer
/// sent twice must have let go of both.
#[test]
fn a_buffer_a_silent_session_was_sent_stays() {
    let pool = Pool::open(settings(256 * 1024));
    let ledger = &pool.provider.as_ref().unwrap().ledger;
    ledger.attach();
    let (killed, live) = (dead(), process::session_id());
    let stranger = "1f2e3d4c5b6a79881f2e3d4c5b6a7988";
    let _held = sent_stamped(&pool, &[&killed, &live, stranger], (7, 1));
    gone(&pool, &killed);
    let asked = ledger.to_ask(std::time::Instant::now()).unwrap();
    ledger.answered(asked, &answer(&live, 9, &[]));
    assert_eq!(
        reclaim_later(&pool, GRACE * 100),
        0,
        "the stranger may hold it"
    );
    assert_eq!(pool.usage().gone_held, 1);
    let not_reading = asking::Answer {
        reader: stranger.to_owned(),
        receives: false,
        publishers: Vec::new(),
    };
    ledger.answered(asked, &not_reading);
    assert_eq!(reclaim_later(&pool, GRACE), 0, "the grace");
    assert_eq!(
        reclaim_later(&pool, GRACE * 3),
        1,
        "it reads nothing of ours"
    );
    // Numbers wrap: one far ahead of the last seen reads as not seen yet.
    assert!(asking::at_or_after(3, u32::MAX - 2));
    assert!(!asking::at_or_after(u32::MAX - 2, 3));
    let twice = [(7, 5), (7, 9)];
    assert!(!answer(&live, 9, &[5]).done_with(&twice));
    assert!(!answer(&live, 8, &[]).done_with(&twice));
    assert!(answer(&live, 9, &[]).done_with(&twice));
    assert!(!answer(&live, 9, &[]).done_with(&[]), "sent unstamped");
}

/// The session id of a process that has ended (a ferroc part's, [`process`]).
fn dead() -> String {
    let mut child = std::process::Command::new("true").spawn().unwrap();
    child.wait().unwrap();
    process::id_for(child.id())
}

fn gone(pool: &Pool, peer: &str) {
    let ledger = &pool.provider.as_ref().unwrap().ledger;
    ledger.transport(peer.to_string(), false, std::time::Instant::now());
}

/// What the ledger gives back at `later` than now.
fn reclaim_later(pool: &Pool, later: Duration) -> usize {
    let provider = pool.provider.as_ref().unwrap();
    let at = std::time::Instant::now() + later;
    provider.ledger.reclaim(at, &provider.chunks)
}

/// A buffer only a session that is gone holds (a reader killed holding it) comes back
/// once that session has been gone for the grace; its count stays in Zenoh's header,
/// which the ledger keeps, so nothing frees the chunk twice.
#[test]
fn a_buffer_only_gone_sessions_hold_comes_back_after_the_grace() {
    let pool = Pool::open(settings(64 * 1024));
    pool.provider.as_ref().unwrap().ledger.attach();
    let reader = dead();
    let dead = sent_and_held(&pool, &[&reader]);
    assert_eq!(pool.room_for(40_000), Some(0), "the reader holds it");
    gone(&pool, &reader);
    assert_eq!(reclaim_later(&pool, GRACE / 2), 0, "not within the grace");
    assert_eq!(reclaim_later(&pool, GRACE), 1);
    assert_eq!(pool.room_for(40_000), Some(1), "back, though still counted");
    assert_eq!(pool.usage().reclaimed, 1);
    let fresh = pool.payload(vec![3; 40_000], false, "link");
    assert!(matches!(fresh, Payload::Shared(_)), "{fresh:?}");
    drop(dead); // (a killed reader never does this; a stray count changes nothing)
    assert_eq!(pool.room_for(40_000), Some(0), "the fresh value holds it");
    drop(fresh);
    assert_eq!(pool.room_for(40_000), Some(1));
}

/// The silent side: a buffer a live process may hold is never given back, however
/// long it holds it and even if its transport closed; nor one sent to a session not
/// known to be a ferroc part, one its output still holds, one not sent yet, one sent
/// by a session since closed, or one sent to no session at all.
#[test]
fn a_buffer_a_live_session_may_hold_is_kept_however_long() {
    let pool = Pool::open(settings(256 * 1024));
    let ledger = &pool.provider.as_ref().unwrap().ledger;
    ledger.attach();
    // A transport closed, but its process lives (starved past the lease): kept.
    let (live, killed) = (process::session_id(), dead());
    let slow = sent_and_held(&pool, &[&live, &killed]);
    gone(&pool, &killed);
    gone(&pool, &live);
    assert_eq!(reclaim_later(&pool, GRACE * 100), 0, "slow still reads it");
    // Another Zenoh program (its id names no process): kept.
    let stranger = "1f2e3d4c5b6a79881f2e3d4c5b6a7988";
    let other = sent_and_held(&pool, &[stranger]);
    gone(&pool, stranger);
    assert_eq!(reclaim_later(&pool, GRACE * 100), 0, "not known to be dead");
    assert!(slow.iter().all(|b| *b == 9), "intact");
    // Lent and sent, while the output still holds it: kept although its reader left.
    let mut lent = pool.lend(40_000).unwrap();
    lent.bytes_mut().unwrap().fill(5);
    let lent_zenoh = lent.as_any().downcast_ref::<Lent>().unwrap().shared();
    let read = lent_zenoh.as_shm().unwrap().to_owned();
    let lent_reader = dead();
    ledger.transport(lent_reader.clone(), true, std::time::Instant::now());
    pool.sent(&[reclaim::address(&read)], None);
    drop(lent_zenoh);
    gone(&pool, &lent_reader);
    assert_eq!(reclaim_later(&pool, GRACE * 100), 0, "the output holds it");
    assert!(lent.bytes_mut().is_none(), "and its reader's count stays");
    // Put, but not noted as sent (on its way): kept.
    let on_its_way = pool.payload(vec![1; 40_000], false, "link");
    let Payload::Shared(way) = &on_its_way else {
        panic!()
    };
    let _way_reader = way.as_shm().unwrap().to_owned();
    drop(on_its_way);
    assert_eq!(reclaim_later(&pool, GRACE * 100), 0, "on its way");
    // Sent by a session the part has since closed: who holds it cannot be known.
    let old = dead();
    let before = sent_and_held(&pool, &[&old]);
    ledger.detach();
    ledger.attach();
    gone(&pool, &old);
    assert_eq!(
        reclaim_later(&pool, GRACE * 100),
        0,
        "sent by an older session"
    );
    drop((slow, other, read, before));
    // Sent while no transport was open: whoever holds it is in this process.
    let alone = Pool::open(settings(64 * 1024));
    alone.provider.as_ref().unwrap().ledger.attach();
    let _local = sent_and_held(&alone, &[]);
    assert_eq!(
        reclaim_later(&alone, GRACE * 100),
        0,
        "held in this process"
    );
}

/// A part that closes its session after its reader was gone still gets that
/// reader's buffers back: the session saw every holder go before it closed.
#[test]
fn a_gone_readers_buffer_comes_back_after_the_part_closed_its_session() {
    let pool = Pool::open(settings(64 * 1024));
    pool.provider.as_ref().unwrap().ledger.attach();
    let reader = dead();
    let _dead = sent_and_held(&pool, &[&reader]);
    gone(&pool, &reader);
    pool.detach();
    assert_eq!(reclaim_later(&pool, GRACE), 1);
    assert_eq!(pool.room_for(40_000), Some(1));
}

/// A lent buffer its output still held when the part closed its session, every reader
/// it was sent to gone before: it comes back once the output lets go, and meanwhile
/// it does not count as waiting for readers (`gone_held`).
#[test]
fn a_lent_buffer_held_at_close_comes_back_once_its_output_lets_go() {
    let pool = Pool::open(settings(64 * 1024));
    let ledger = &pool.provider.as_ref().unwrap().ledger;
    ledger.attach();
    let reader = dead();
    ledger.transport(reader.clone(), true, std::time::Instant::now());
    let mut lent = pool.lend(40_000).unwrap();
    lent.bytes_mut().unwrap().fill(5);
    let sent = lent.as_any().downcast_ref::<Lent>().unwrap().shared();
    let killed_holds = sent.as_shm().unwrap().to_owned();
    pool.sent(&[reclaim::address(&killed_holds)], Some((7, 1)));
    drop(sent);
    gone(&pool, &reader);
    assert_eq!(pool.usage().gone_held, 0, "its output holds it");
    pool.detach();
    assert_eq!(reclaim_later(&pool, GRACE * 2), 0, "its output holds it");
    drop(lent);
    assert_eq!(reclaim_later(&pool, GRACE * 3), 0, "the grace");
    assert_eq!(reclaim_later(&pool, GRACE * 5), 1);
    assert_eq!(pool.room_for(40_000), Some(1));
    drop(killed_holds);
}
