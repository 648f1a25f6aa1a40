//! Zenoh's runtime threads of a part program (`config::runtime`, docs/zenoh.md
//! "Tuning"): with ferroc's default, the connection a part accepts is accepted and
//! read on Zenoh's receive runtime, so the program has no acceptor thread at all; a
//! `ZENOH_RUNTIME` of the user's wins. Each case runs in a program of its own (Zenoh
//! reads the variable once per process): this test binary again, running only the
//! ignored `runtime_program`, which prints what it set and its threads' names.

use ferroc_runtime::link::transport::Addresses;
use ferroc_zenoh::config::{config, runtime};
use std::collections::BTreeMap;
use std::process::Command;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};
use zenoh::Wait;

/// Runs `runtime_program` with `ZENOH_RUNTIME` = `value` (none when `None`): what it
/// set, and its threads' names.
fn program(value: Option<&str>) -> (String, Vec<String>) {
    let mut command = Command::new(std::env::current_exe().unwrap());
    command.args(["runtime_program", "--exact", "--ignored", "--nocapture"]);
    match value {
        Some(v) => command.env(runtime::ENV, v),
        None => command.env_remove(runtime::ENV),
    };
    let out = command.output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let line = |key: &str| {
        (stdout.lines())
            .find_map(|l| l.strip_prefix(key))
            .unwrap_or_else(|| panic!("no `{key}` in:\n{stdout}"))
            .to_string()
    };
    let threads = line("THREADS ").split(',').map(str::to_string).collect();
    (line("SET "), threads)
}

#[test]
fn a_part_program_accepts_and_reads_its_connections_on_the_receive_runtime() {
    let (set, threads) = program(None);
    assert_eq!(set, format!("{:?}", Some(runtime::DEFAULT)));
    assert!(threads.iter().any(|t| t.starts_with("rx-")), "{threads:?}");
    assert!(
        !threads.iter().any(|t| t.starts_with("acc-")),
        "an acceptor thread: {threads:?}"
    );
}

#[test]
fn a_zenoh_runtime_in_the_environment_wins() {
    // Zenoh's own threads: the accepted connection's socket belongs to the acceptor.
    let (set, threads) = program(Some("()"));
    assert_eq!(set, "None");
    assert!(threads.iter().any(|t| t == "acc-0"), "{threads:?}");
}

/// The part `part` listening on `all[part]`, connecting to the others in `all`.
fn session(part: &str, all: &BTreeMap<String, String>) -> zenoh::Session {
    let addresses = Addresses {
        part: part.into(),
        listen: all[part].clone(),
        peers: all.clone(),
    };
    zenoh::open(config(&addresses, None).unwrap())
        .wait()
        .unwrap()
}

/// One program of the tests above: part `b` listens, part `a` connects to it and puts
/// until `b` received a value, so `b` accepted the connection and read from it.
#[test]
#[ignore = "run by the tests above, as a program of its own"]
fn runtime_program() {
    let set = runtime::use_default();
    let b_only: BTreeMap<String, String> =
        [("b".to_string(), ferroc_testkit::free_address())].into();
    let b = session("b", &b_only);
    let mut both = b_only.clone();
    both.insert("a".into(), ferroc_testkit::free_address());
    let a = session("a", &both);
    let got = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&got);
    let key = "ferroc-test/runtime";
    let _sub = (b.declare_subscriber(key))
        .callback(move |_| flag.store(true, Ordering::SeqCst))
        .wait()
        .unwrap();
    let limit = Instant::now() + Duration::from_secs(20);
    while !got.load(Ordering::SeqCst) && Instant::now() < limit {
        a.put(key, "x").wait().unwrap();
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(got.load(Ordering::SeqCst), "b received nothing from a");
    let mut threads: Vec<String> = std::fs::read_dir("/proc/self/task")
        .unwrap()
        .filter_map(|t| std::fs::read_to_string(t.ok()?.path().join("comm")).ok())
        .map(|name| name.trim().to_string())
        .collect();
    threads.sort();
    println!("SET {set:?}");
    println!("THREADS {}", threads.join(","));
}
