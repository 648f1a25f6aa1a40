//! A shared-memory pool that stays full for a long time (zenoh-link/src/shm/mod.rs,
//! docs/zenoh.md "the pool is full"), for real: `/dev/shm`, two part programs (this
//! test binary started again as `camera_program` and as `reader_program`), a 64 KiB
//! pool with room for eight 8 kB frames, and a reader that keeps its first eight frames
//! where they arrived, so the pool has no room left.
//!
//! Under both of a link's `on-full` policies the camera's warning names the link and is
//! throttled (the 1st, 10th, 100th … time: as many lines as powers of ten up to the
//! count), and the run goes on: dropping, the camera keeps stepping and sends in shared
//! memory again once the reader lets go; blocking, a value waits for room at most
//! 500 ms and then reaches the reader over the network. No assertion depends on speed:
//! the tests wait (with generous limits) for counts.

#[allow(dead_code)] // the parts of tests/shm.rs: this file uses a few of them
#[path = "support/shm_parts.rs"]
mod shm_parts;
mod support;

use ferroc_runtime::builder::{Builder, StartOptions};
use ferroc_runtime::module::Value;
use shm_parts::{config_file, link, peers, registry, zenoh, Reader};
use std::collections::BTreeMap;
use std::io::{BufRead, BufReader, Read, Write};
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::Duration;
use support::eventually;

/// The reader program (started by the tests; does nothing otherwise).
#[test]
#[ignore = "the reader program the other tests start"]
fn reader_program() {
    shm_parts::reader_program();
}

/// The size of a frame: eight fit the 64 KiB pool, nine do not.
const FRAME: usize = 8_000;

/// The reader keeps its first this many frames (`Viewer`'s `hold`): the pool's all.
const KEEP_FIRST: i64 = -8;

/// The pool: Zenoh's (and ferroc's) smallest, 64 KiB.
const POOL: &str =
    "{ transport: { shared_memory: { transport_optimization: { pool_size: 65536 } } } }";

/// The camera program: the `cam` part of `FERROC_SHM_CAMERA` = "APP CAM_ADDR VIEW_ADDR
/// RELIABLE CONFIG", an 8 kB frame every 2 ms on a link that is reliable (1) or not,
/// saying `used SHARED NETWORK DROPPED` every 50 ms until its standard input closes,
/// then `final …` once it has stopped. Its warnings go to standard error.
#[test]
#[ignore = "the camera program the other tests start"]
fn camera_program() {
    let Some((words, peers)) = shm_parts::program_spec("FERROC_SHM_CAMERA") else {
        return;
    };
    let registry = registry();
    let cam = zenoh(&words[0], "cam", &peers, Some(&PathBuf::from(&words[4])));
    let params = [("size".to_string(), Value::Float(FRAME as f64))];
    let mut b = Builder::new(&registry);
    shm_parts::add_part(&mut b, "cam", 2, &params);
    let spec = link(words[3] == "1");
    b.link_out(&spec, ("cam/camera", "out"), Default::default())
        .unwrap();
    let options = StartOptions {
        network: Some(Arc::clone(&cam) as _),
        ..StartOptions::default()
    };
    let app = b.start_with(options).unwrap();
    let say = |word: &str| {
        let used = cam.shm_use();
        println!("{word} {} {} {}", used.shared, used.network, used.dropped);
        let _ = std::io::stdout().flush();
    };
    let (tx, rx) = std::sync::mpsc::channel::<()>();
    std::thread::spawn(move || {
        let _ = std::io::stdin().read_to_end(&mut Vec::new());
        let _ = tx.send(());
    });
    while rx.recv_timeout(Duration::from_millis(50)).is_err() {
        say("used");
    }
    app.stop();
    say("final");
}

/// The camera program, its counts and its warnings.
struct Camera {
    child: Child,
    out: Arc<Mutex<Vec<String>>>,
    err: Arc<Mutex<Vec<String>>>,
}

/// Collects the lines of `stream` into a shared list.
fn collect(stream: impl Read + Send + 'static) -> Arc<Mutex<Vec<String>>> {
    let lines: Arc<Mutex<Vec<String>>> = Arc::default();
    let into = Arc::clone(&lines);
    std::thread::spawn(move || {
        for line in BufReader::new(stream).lines().map_while(Result::ok) {
            into.lock().unwrap().push(line);
        }
    });
    lines
}

impl Camera {
    fn start(app: &str, peers: &BTreeMap<String, String>, reliable: bool) -> Camera {
        let config = config_file(&format!("{app}.json5"), POOL);
        let spec = format!(
            "{app} {} {} {} {}",
            peers["cam"],
            peers["view"],
            u8::from(reliable),
            config.display()
        );
        let mut child = Command::new(std::env::current_exe().unwrap())
            .args(["camera_program", "--exact", "--ignored", "--nocapture"])
            .env("FERROC_SHM_CAMERA", spec)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let out = collect(child.stdout.take().unwrap());
        let err = collect(child.stderr.take().unwrap());
        Camera { child, out, err }
    }

    /// The latest counts it said (`used` or `final`): shared, network, dropped.
    fn counts(&self, word: &str) -> Option<[u64; 3]> {
        let out = self.out.lock().unwrap();
        out.iter().rev().find_map(|l| {
            let w: Vec<u64> = (l.strip_prefix(word)?.split_whitespace())
                .map(|n| n.parse().ok())
                .collect::<Option<_>>()?;
            w.try_into().ok()
        })
    }

    fn used(&self) -> [u64; 3] {
        self.counts("used ").unwrap_or_default()
    }

    /// Stops it (its input closes): its final counts and its standard error.
    fn stop(mut self) -> ([u64; 3], Vec<String>) {
        drop(self.child.stdin.take());
        let status = self.child.wait().unwrap();
        // The pipes' readers finish once the program is gone.
        let done = eventually(Duration::from_secs(10), || self.counts("final ").is_some());
        let out = self.out.lock().unwrap().clone();
        assert!(status.success() && done, "{status}: {out:?}");
        let err = self.err.lock().unwrap().clone();
        (self.counts("final ").unwrap(), err)
    }
}

/// How many times a warning said `n` times is shown: the 1st, 10th, 100th … time.
fn shown(n: u64) -> usize {
    (0..20).take_while(|&k| 10u64.pow(k) <= n).count()
}

/// The camera's warnings containing `what`: each names the link, there are exactly as
/// many as the throttle shows for `count` occurrences, and no other about the pool.
fn throttled(err: &[String], what: &str, count: u64) {
    let lines: Vec<&String> = err.iter().filter(|l| l.contains(what)).collect();
    assert_eq!(lines.len(), shown(count), "{count} times: {err:#?}");
    for line in &lines {
        assert!(
            line.starts_with("warning: link cam → view ("),
            "not naming the link: {line}"
        );
    }
    let others: Vec<&String> = (err.iter())
        .filter(|l| l.contains("pool") && !l.contains(what))
        .collect();
    assert!(others.is_empty(), "{others:#?}");
}

#[test]
fn a_pool_full_for_long_on_a_link_that_drops_warns_a_few_times_and_the_camera_goes_on() {
    let name = "shm_full_drop";
    let peers = peers();
    // The reader keeps its first frames where they arrived: the pool is full from then
    // on, and no new frame reaches the reader.
    let first = Reader::start_with(name, &peers["cam"], &peers["view"], KEEP_FIRST, 5);
    let camera = Camera::start(name, &peers, false);
    let long = eventually(Duration::from_secs(120), || camera.used()[2] >= 300);
    assert!(long, "{:?}: {:?}", camera.used(), first.seen());
    let [shared, _, _] = camera.used();
    assert!(shared >= 1, "{:?}", camera.used());
    // The reader lets go (it ends): its frames come back, and the camera, which kept
    // stepping all along, sends in shared memory again to a new reader.
    drop(first);
    let again = Reader::start(name, &peers);
    let sent_again = eventually(Duration::from_secs(120), || {
        camera.used()[0] > shared + 20 && again.seen().len() >= 5
    });
    assert!(sent_again, "{:?}: {:?}", camera.used(), again.seen());
    assert!(again.seen().iter().all(|(size, ok)| *size == FRAME && *ok));
    let ([_, network, dropped], err) = camera.stop();
    assert_eq!(network, 0);
    assert!(dropped >= 300, "{dropped}");
    throttled(&err, "the shared-memory pool is full", dropped);
}

#[test]
fn a_pool_full_for_long_on_a_reliable_link_warns_a_few_times_and_values_take_the_network() {
    let name = "shm_full_block";
    let peers = peers();
    let reader = Reader::start_with(name, &peers["cam"], &peers["view"], KEEP_FIRST, 5);
    let camera = Camera::start(name, &peers, true);
    // Every value waits 500 ms for room, then takes the network and arrives, intact.
    let long = eventually(Duration::from_secs(120), || {
        camera.used()[1] >= 12 && reader.seen().len() >= 20
    });
    assert!(long, "{:?}: {:?}", camera.used(), reader.seen());
    assert!(reader.seen().iter().all(|(size, ok)| *size == FRAME && *ok));
    let ([_, network, dropped], err) = camera.stop();
    drop(reader);
    assert_eq!(dropped, 0, "a reliable link drops nothing");
    throttled(
        &err,
        "the shared-memory pool stayed full for 500 ms",
        network,
    );
}
