//! Shared memory between part programs (zenoh-link/src/shm.rs), for real: `/dev/shm`,
//! two Zenoh sessions on 127.0.0.1, the reader in its own process (this test binary
//! started again as `reader_program`) where a test kills it.
//!
//! A camera part sends `ferroc_std.Image`s whose bytes all say which frame they are,
//! so a reader can tell a torn or reused buffer from an intact one; the reader prints
//! `seen SEQ SIZE ok|bad` per frame and how many values arrived in shared memory.
//! No assertion depends on speed: the tests wait (with generous limits) for counts.

#[path = "support/shm_parts.rs"]
mod shm_parts;
mod support;

use ferroc_runtime::builder::{Builder, ModuleSpec, Schedule, StartOptions, StepKind, ThreadSpec};
use ferroc_runtime::container::ThreadOptions;
use ferroc_runtime::link::LinkSpec;
use ferroc_runtime::module::Value;
use ferroc_runtime::port::ConnectOptions;
use ferroc_zenoh::shm::Pool;
use shm_parts::*;
use std::collections::BTreeMap;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::Duration;
use support::{eventually, free_port, lines_of};

/// The reader program of the tests below (started by them; does nothing otherwise).
#[test]
#[ignore = "the reader program the other tests start"]
fn reader_program() {
    shm_parts::reader_program();
}

#[test]
fn values_of_every_size_arrive_intact_across_two_programs() {
    every_size_arrives_intact("shm_sizes", false);
}

/// The camera fills buffers its output lends (`Out::lend`): the large ones are pool
/// buffers sent without a copy, the 64 B one plain memory; all arrive intact, the
/// large ones read in place.
#[test]
fn lent_values_of_every_size_arrive_intact_across_two_programs() {
    every_size_arrives_intact("shm_lent", true);
}

fn every_size_arrives_intact(name: &str, lend: bool) {
    let registry = registry();
    let peers = peers();
    let cam = zenoh(name, "cam", &peers, None);
    let reader = Reader::start(name, &peers);
    let app = camera_with(&registry, &cam, 20, 0, lend);
    let every_size = eventually(Duration::from_secs(120), || {
        let seen = reader.seen();
        SIZES
            .iter()
            .all(|s| seen.iter().filter(|(size, ok)| size == s && *ok).count() >= 2)
            && reader.received_shared() > 0
    });
    app.stop();
    drop(app);
    let seen = reader.seen();
    assert!(every_size, "frames seen: {seen:?}");
    assert!(
        seen.iter().all(|(_, ok)| *ok),
        "a frame arrived torn: {seen:?}"
    );
    let used = cam.shm_use();
    assert!(used.active && used.shared > 0, "{used:?}");
    assert_eq!(used.dropped, 0, "{used:?}");
    // Lent: every large value went in its lent buffer; otherwise none did.
    match lend {
        true => assert!(used.lent > 0 && used.lent == used.shared, "{used:?}"),
        false => assert_eq!(used.lent, 0, "{used:?}"),
    }
    // Large frames are read where they arrived, in the writer's shared memory; small
    // ones (under the 4 KB threshold) are not in shared memory and own their bytes.
    let (in_place, owned) = reader.places();
    for size in &SIZES[1..] {
        assert!(
            in_place.contains(size),
            "{size} B never read in place: {seen:?}"
        );
    }
    assert!(!in_place.contains(&SIZES[0]), "64 B read in place");
    assert!(owned.contains(&SIZES[0]), "{owned:?}");
}

/// A reader killed while frames flow: the camera goes on in shared memory, a new reader
/// receives, and every buffer the killed reader held comes back once its session is
/// gone (zenoh-link/src/shm/reclaim.rs): once the second reader has stopped normally,
/// the pool has room for exactly as many frames as a fresh one.
#[test]
fn a_reader_killed_while_holding_buffers_leaks_none_and_a_new_one_receives() {
    killed_reader("shm_kill", false);
}

/// The same with frames in buffers the camera's output lends.
#[test]
fn a_reader_killed_while_holding_lent_buffers_leaks_none() {
    killed_reader("shm_kill_lent", true);
}

fn killed_reader(name: &str, lend: bool) {
    let registry = registry();
    let peers = peers();
    let cam = zenoh(name, "cam", &peers, None);
    let app = camera_with(&registry, &cam, 20, SIZES[3], lend);
    let first = Reader::start(name, &peers);
    assert!(eventually(Duration::from_secs(60), || first.seen().len() >= 10));
    first.kill();
    let second = Reader::start(name, &peers);
    let again = eventually(Duration::from_secs(60), || second.seen().len() >= 10);
    assert!(again, "the restarted reader saw {:?}", second.seen());
    assert!(second.seen().iter().all(|(_, ok)| *ok));
    // What the killed reader held (at least the frame its input read in place) came
    // back while the camera ran, and the camera went on in shared memory.
    let reclaimed = eventually(Duration::from_secs(60), || cam.shm_use().reclaimed > 0);
    assert!(reclaimed, "nothing came back: {:?}", cam.shm_use());
    let sent = cam.shm_use().shared;
    let going_on = eventually(Duration::from_secs(60), || cam.shm_use().shared > sent + 5);
    assert!(going_on, "the camera stopped sending in shared memory");
    app.stop();
    drop(app);
    let fresh = Pool::open(cam.shm_settings()).room_for(SIZES[3]).unwrap();
    let room = || cam.shm_room_for(SIZES[3]).unwrap_or(0);
    drop(second);
    // The second reader ended normally: its buffers come back; the killed reader's
    // came back already. None is missing.
    let back = eventually(Duration::from_secs(20), || room() == fresh);
    assert!(
        back,
        "the pool lost buffers: room for {} of {fresh} ({:?})",
        room(),
        cam.shm_use()
    );
}

/// The silent side: a live reader that holds buffers long (it keeps its first frames,
/// sent to the other reader too, read in place, and checks them all again at every
/// step, stepping slowly) keeps them while another reader is killed; in a small pool
/// that reuses its buffers at once, none of the kept frames changes under it. The
/// killed reader's other buffers, which the live one was sent too, come back while it
/// runs, as it answers that it let go of them (shm/asking.rs), never one it still holds.
#[test]
fn a_slow_live_reader_keeps_its_buffers_while_another_is_killed() {
    slow_reader("shm_slow", false);
}

/// The same with frames in buffers the camera's output lends (read in pieces).
#[test]
fn a_slow_live_reader_keeps_its_lent_buffers_while_another_is_killed() {
    slow_reader("shm_slow_lent", true);
}

fn slow_reader(name: &str, lend: bool) {
    let registry = registry();
    let peers = peers();
    // 12 MiB: twelve 1 MiB frames, so freed buffers are written again at once.
    let small = config_file(
        "slow.json5",
        "{ transport: { shared_memory: { transport_optimization: { pool_size: 12582912 } } } }",
    );
    let cam = zenoh(name, "cam", &peers, Some(&small));
    let app = camera_with(&registry, &cam, 20, SIZES[2], lend);
    // The killed reader first: the frames the slow one keeps were sent to both.
    let killed = Reader::start(name, &peers);
    assert!(eventually(Duration::from_secs(60), || killed.seen().len() >= 5));
    let slow = Reader::start_with(name, &peers["cam"], &free_port(), -3, 100);
    let both = eventually(Duration::from_secs(60), || {
        slow.held_checks().len() >= 5 && killed.seen().len() >= 5
    });
    assert!(both, "{:?} {:?}", slow.seen(), killed.seen());
    killed.kill();
    // The slow reader goes on checking its kept frames while the pool reuses buffers.
    let (checks, sent) = (slow.held_checks().len(), cam.shm_use().shared);
    let more = eventually(Duration::from_secs(60), || {
        slow.held_checks().len() >= checks + 10 && cam.shm_use().shared > sent + 30
    });
    assert!(more, "{:?} {:?}", slow.held_checks(), cam.shm_use());
    let reclaimed = eventually(Duration::from_secs(60), || cam.shm_use().reclaimed > 0);
    assert!(
        reclaimed,
        "the killed reader's buffers: {:?}",
        cam.shm_use()
    );
    let checks = slow.held_checks().len();
    let after = eventually(Duration::from_secs(60), || {
        slow.held_checks().len() >= checks + 10
    });
    assert!(after, "{:?}", slow.held_checks());
    let held = slow.held_checks();
    assert!(held.iter().all(|ok| *ok), "a kept frame changed: {held:?}");
    assert!(slow.seen().iter().all(|(_, ok)| *ok), "{:?}", slow.seen());
    drop(slow); // stops normally
    app.stop();
    drop(app);
    let fresh = Pool::open(cam.shm_settings()).room_for(SIZES[2]).unwrap();
    let room = || cam.shm_room_for(SIZES[2]).unwrap_or(0);
    let back = eventually(Duration::from_secs(20), || room() == fresh);
    assert!(back, "room for {} of {fresh}: {:?}", room(), cam.shm_use());
}

/// Three readers of the same frames, one killed mid-stream: its buffers all come back
/// while the other two keep reading (they answer which buffers they still hold:
/// shm/asking.rs), without waiting for them to stop. Meanwhile the two keep receiving
/// intact frames and keep their last three, read in place, unchanged, in a small pool
/// that reuses every buffer that comes back at once. In the end the pool has room for
/// exactly as many frames as a fresh one.
#[test]
fn a_killed_reader_among_three_leaks_nothing_while_the_others_read_on() {
    killed_among_three("shm_three", false);
}

/// The same with frames in buffers the camera's output lends (read in pieces).
#[test]
fn a_killed_reader_among_three_lent_to_leaks_nothing_while_the_others_read_on() {
    killed_among_three("shm_three_lent", true);
}

fn killed_among_three(name: &str, lend: bool) {
    let registry = registry();
    let peers = peers();
    let small = config_file(
        "three.json5",
        "{ transport: { shared_memory: { transport_optimization: { pool_size: 12582912 } } } }",
    );
    let cam = zenoh(name, "cam", &peers, Some(&small));
    let app = camera_with(&registry, &cam, 20, SIZES[2], lend);
    let live = [0, 1].map(|_| Reader::start_with(name, &peers["cam"], &free_port(), 3, 20));
    let killed = Reader::start_with(name, &peers["cam"], &peers["view"], 3, 20);
    let all = eventually(Duration::from_secs(60), || {
        killed.held_checks().len() >= 5 && live.iter().all(|r| r.held_checks().len() >= 5)
    });
    assert!(
        all,
        "{:?} {:?}",
        killed.seen(),
        live.each_ref().map(Reader::seen)
    );
    killed.kill();
    // Its buffers come back and none stays counted for it, the others still reading.
    let back = eventually(Duration::from_secs(60), || {
        let used = cam.shm_use();
        used.reclaimed > 0 && used.gone_held == 0
    });
    assert!(back, "{:?}", cam.shm_use());
    let (seen, sent) = (
        live.each_ref().map(|r| r.seen().len()),
        cam.shm_use().shared,
    );
    let on = eventually(Duration::from_secs(60), || {
        live.iter()
            .zip(&seen)
            .all(|(r, n)| r.seen().len() >= n + 20)
            && cam.shm_use().shared > sent + 20
    });
    assert!(
        on,
        "{:?} {:?}",
        live.each_ref().map(Reader::seen),
        cam.shm_use()
    );
    for reader in &live {
        let held = reader.held_checks();
        assert!(held.iter().all(|ok| *ok), "a kept frame changed: {held:?}");
        assert!(
            reader.seen().iter().all(|(_, ok)| *ok),
            "{:?}",
            reader.seen()
        );
    }
    app.stop();
    drop(app);
    drop(live); // stop normally
    let fresh = Pool::open(cam.shm_settings()).room_for(SIZES[2]).unwrap();
    let room = || cam.shm_room_for(SIZES[2]).unwrap_or(0);
    let none_lost = eventually(Duration::from_secs(20), || room() == fresh);
    assert!(
        none_lost,
        "room for {} of {fresh}: {:?}",
        room(),
        cam.shm_use()
    );
}

/// The silent side with a reader that is not a ferroc part (Python's `eclipse-zenoh`,
/// which receives the frames' bytes over the network): it cannot say which buffers it
/// holds, so a killed ferroc reader's buffers that it was sent too stay counted while
/// it lives, as before there was any asking.
#[test]
fn a_killed_readers_buffers_also_sent_to_a_python_client_stay() {
    let Some(python) = ferroc_testkit::python(&["zenoh"]) else {
        return;
    };
    let name = "shm_python";
    let registry = registry();
    let peers = peers();
    let cam = zenoh(name, "cam", &peers, None);
    let app = camera_with(&registry, &cam, 20, SIZES[2], false);
    let killed = Reader::start_with(name, &peers["cam"], &peers["view"], 3, 20);
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/python/hold_on.py");
    let mut client = Command::new(python)
        .arg(script)
        .args([format!("tcp/{}", peers["cam"]), name.to_string()])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let samples = Arc::new(AtomicUsize::new(0));
    let (stdout, count) = (client.stdout.take().unwrap(), Arc::clone(&samples));
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            if line.starts_with("sample ") {
                count.fetch_add(1, Ordering::Relaxed);
            }
        }
    });
    let both = eventually(Duration::from_secs(60), || {
        samples.load(Ordering::Relaxed) >= 5 && killed.held_checks().len() >= 5
    });
    assert!(both, "python: {samples:?}, reader: {:?}", killed.seen());
    killed.kill();
    // The client keeps receiving, the camera keeps sending in shared memory, past the
    // grace many times over; nothing the client was sent comes back.
    let (got, sent) = (samples.load(Ordering::Relaxed), cam.shm_use().shared);
    let on = eventually(Duration::from_secs(60), || {
        samples.load(Ordering::Relaxed) >= got + 250 && cam.shm_use().shared > sent + 250
    });
    let used = cam.shm_use();
    drop(client.stdin.take());
    let _ = client.wait();
    app.stop();
    assert!(on, "python saw {samples:?}: {used:?}");
    assert_eq!(used.reclaimed, 0, "{used:?}");
    assert!(used.gone_held > 0, "the killed one's share stays: {used:?}");
}

/// The silent side again, where transports fail: a reader stopped (SIGSTOP) for much
/// longer than the 500 ms lease loses its transport while it holds frames in place;
/// its process lives, so none of them comes back to the pool, and once it runs again
/// (SIGCONT) every frame it kept is still intact, while the camera went on reusing
/// the rest of a small pool.
#[test]
fn a_reader_stopped_past_the_lease_keeps_its_buffers() {
    let name = "shm_stopped";
    let registry = registry();
    let peers = peers();
    let small = config_file(
        "stopped.json5",
        "{ transport: { shared_memory: { transport_optimization: { pool_size: 12582912 } } } }",
    );
    let cam = zenoh(name, "cam", &peers, Some(&small));
    let app = camera_with(&registry, &cam, 20, SIZES[2], false);
    let reader = Reader::start_with(name, &peers["cam"], &peers["view"], 3, 20);
    let checking = eventually(Duration::from_secs(60), || reader.held_checks().len() >= 5);
    assert!(checking, "{:?}", reader.seen());
    reader.signal("STOP");
    // 40 frames: the pool fills with what the stopped reader holds and what waits in
    // its socket, so a reliable frame waits 500 ms for room before it takes the
    // network: some 20 s, past the lease and the grace many times over.
    let sent = cam.shm_use().shared + cam.shm_use().network;
    let went_on = eventually(Duration::from_secs(120), || {
        let used = cam.shm_use();
        used.shared + used.network > sent + 40
    });
    reader.signal("CONT");
    assert!(went_on, "{:?}", cam.shm_use());
    let checks = reader.held_checks().len();
    let again = eventually(Duration::from_secs(60), || {
        reader.held_checks().len() >= checks + 5
    });
    app.stop();
    drop(app);
    assert!(again, "{:?}", reader.held_checks());
    let held = reader.held_checks();
    assert!(held.iter().all(|ok| *ok), "a kept frame changed: {held:?}");
    assert_eq!(cam.shm_use().reclaimed, 0, "its process lived");
}

#[test]
fn with_shared_memory_off_values_take_the_network_intact() {
    network_only("shm_off", false);
}

/// Shared memory off by configuration: what the output lends is plain memory, and
/// the values take the network, intact.
#[test]
fn with_shared_memory_off_lent_values_are_plain_memory_and_take_the_network_intact() {
    network_only("shm_off_lent", true);
}

fn network_only(name: &str, lend: bool) {
    let registry = registry();
    let peers = peers();
    let off = config_file(
        &format!("{name}.json5"),
        "{ transport: { shared_memory: { enabled: false } } }",
    );
    let cam = zenoh(name, "cam", &peers, Some(&off));
    let reader = Reader::start(name, &peers);
    let app = camera_with(&registry, &cam, 20, 0, lend);
    let arrived = eventually(Duration::from_secs(120), || {
        let seen = reader.seen();
        SIZES
            .iter()
            .all(|s| seen.iter().any(|(size, ok)| size == s && *ok))
    });
    app.stop();
    drop(app);
    assert!(arrived, "{:?}", reader.seen());
    assert!(reader.seen().iter().all(|(_, ok)| *ok));
    let used = cam.shm_use();
    assert!(
        !used.active && used.shared == 0 && used.lent == 0,
        "{used:?}"
    );
    assert_eq!(reader.received_shared(), 0, "nothing came in shared memory");
}

#[test]
fn a_pool_the_computer_cannot_give_falls_back_to_the_network() {
    let registry = registry();
    let peers = peers();
    // 4 EiB: no /dev/shm holds it, so the pool cannot be made (one warning).
    let huge = config_file(
        "huge.json5",
        "{ transport: { shared_memory: { transport_optimization: { pool_size: 4611686018427387904 } } } }",
    );
    let cam = zenoh("shm_huge", "cam", &peers, Some(&huge));
    let view = zenoh("shm_huge", "view", &peers, None);
    let options = StartOptions {
        network: Some(Arc::clone(&view) as _),
        ..StartOptions::default()
    };
    let params = [("tag".to_string(), Value::Float(31.0))];
    let viewer = part(&registry, "view", 5, &params)
        .start_with(options)
        .unwrap();
    let app = camera(&registry, &cam, 20, SIZES[2]);
    let arrived = eventually(Duration::from_secs(60), || lines_of(31, "seen").len() >= 5);
    app.stop();
    viewer.stop();
    drop((app, viewer));
    assert!(arrived, "{:?}", lines_of(31, ""));
    assert!(lines_of(31, "seen").iter().all(|l| l.contains(" ok")));
    assert!(!cam.shm_use().active);
}

/// Both parts in lockstep, once with shared memory (the camera filling buffers its
/// output lends) and once without: the same frames at the same instants.
#[test]
fn lockstep_output_is_the_same_with_and_without_shared_memory() {
    let registry = registry();
    // A long lease: a debug build moving 6 MB instants on a loaded machine can miss
    // the 500 ms lease, and a session that drops loses the instants on its way.
    let on = config_file(
        "lockstep-on.json5",
        "{ transport: { link: { tx: { lease: 10000 } } } }",
    );
    let off = config_file(
        "lockstep-off.json5",
        "{ transport: { link: { tx: { lease: 10000 } }, shared_memory: { enabled: false } } }",
    );
    // With shared memory the camera fills buffers its output lends; without, its own.
    let run = |tag: f64, config: Option<&PathBuf>| {
        let lend = (
            "lend".to_string(),
            Value::Float(if tag == 41.0 { 1.0 } else { 0.0 }),
        );
        let peers = peers();
        let app = format!("shm_lockstep_{tag}");
        let start = |name: &str, ms: u64, params: &[(String, Value)]| {
            let mut options = support::lockstep(12);
            options.network = Some(zenoh(&app, name, &peers, config) as _);
            part(&registry, name, ms, params)
                .start_with(options)
                .unwrap()
        };
        let view = start("view", 25, &[("tag".to_string(), Value::Float(tag))]);
        let cam = start(
            "cam",
            10,
            &[("size".to_string(), Value::Float(0.0)), lend.clone()],
        );
        for app in [&cam, &view] {
            assert!(
                app.wait_timeout(Duration::from_secs(120)),
                "the run did not end"
            );
            assert_eq!(app.failure(), None);
        }
        lines_of(tag as u64, "seen")
    };
    let with = run(41.0, Some(&on));
    let without = run(42.0, Some(&off));
    assert!(with.len() >= 3, "{with:?}");
    assert!(
        with.iter().any(|l| l.contains(&format!(" {} ", SIZES[3]))),
        "{with:?}"
    );
    assert_eq!(with, without);
}

/// One camera output linked to two reading parts: each value goes out once (one pool
/// buffer, one message naming both links), and each reader takes its own link's
/// frames, intact.
#[test]
fn one_output_to_two_parts_is_sent_once_and_both_receive_it_intact() {
    let registry = registry();
    let peers: BTreeMap<String, String> = ["cam", "view", "view2"]
        .iter()
        .map(|p| (p.to_string(), free_port()))
        .collect();
    let to = |id, to_part| LinkSpec {
        id,
        to_part,
        ..link(true)
    };
    let viewer = |name: &'static str, id: u32, tag: f64| {
        let mut b = Builder::new(&registry);
        let path = format!("{name}/viewer");
        let params = [("tag".to_string(), Value::Float(tag))];
        b.add_module(ModuleSpec {
            path: &path,
            type_name: "test.Viewer",
            params: &params,
            queues: &[],
            ports: &[],
            violations: Default::default(),
        })
        .unwrap();
        b.add_thread(ThreadSpec {
            path: name.into(),
            schedule: Schedule::Periodic(Duration::from_millis(5)),
            options: ThreadOptions::default(),
            steps: vec![(path.clone(), StepKind::Update)],
        })
        .unwrap();
        b.link_in(&to(id, name), (&path, "in"), ConnectOptions::default())
            .unwrap();
        let options = StartOptions {
            network: Some(zenoh("shm_fanout", name, &peers, None) as _),
            ..StartOptions::default()
        };
        b.start_with(options).unwrap()
    };
    let views = [viewer("view", 0, 51.0), viewer("view2", 1, 52.0)];
    let mut b = Builder::new(&registry);
    let params = [("size".to_string(), Value::Float(SIZES[2] as f64))];
    add_part(&mut b, "cam", 20, &params);
    for spec in [to(0, "view"), to(1, "view2")] {
        b.link_out(&spec, ("cam/camera", "out"), Default::default())
            .unwrap();
    }
    let cam = zenoh("shm_fanout", "cam", &peers, None);
    let options = StartOptions {
        network: Some(Arc::clone(&cam) as _),
        ..StartOptions::default()
    };
    let app = b.start_with(options).unwrap();
    let both = eventually(Duration::from_secs(60), || {
        lines_of(51, "seen").len() >= 5 && lines_of(52, "seen").len() >= 5
    });
    app.stop();
    for view in views {
        view.stop();
    }
    assert!(both, "{:?} {:?}", lines_of(51, ""), lines_of(52, ""));
    for tag in [51, 52] {
        assert!(lines_of(tag, "seen").iter().all(|l| l.contains(" ok")));
    }
    let used = cam.shm_use();
    assert!(used.shared > 0 && used.dropped == 0, "{used:?}");
}
