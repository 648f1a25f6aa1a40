//! The Zenoh session of `ferroc run` for a model whose parts are ROS 2 nodes
//! (`ferroc_zenoh::ros2::network::Ros2Network`, docs/zenoh.md), between two runs on
//! this computer: a talker node publishing its clock's tick as /tick and a listener
//! node printing what it receives, peer to peer on loopback (the listener listens, the
//! talker connects, each through `ZENOH_SESSION_CONFIG_URI`).
//!
//! - Without usable shared memory (the talker started in a mount namespace whose
//!   `/dev/shm` is read-only, or missing), the talker warns once and its node
//!   publishes over the network; with the computer's `/dev/shm` nobody warns.
//! - The runner chooses Zenoh's runtime threads first, as a bundle's part program does
//!   (`ferroc_zenoh::config::runtime::use_default`): the listener accepts and reads
//!   the talker's connection on Zenoh's receive runtime, so it has no acceptor thread;
//!   a `ZENOH_RUNTIME` of the user's wins.
//!
//! No assertion depends on speed: the tests wait (bounded) for lines.

mod common;

use common::Killed;

use common::inspected::lines;
use common::no_shm::{self, NoShm};
use common::{tempdir, test_log_dir};
use ferroc_testkit::free_port;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::mpsc::Receiver;
use std::time::{Duration, Instant};

const WARNING: &str = "warning: shared memory is not usable here";

/// The talker's and the listener's models in `dir`.
fn models(dir: &Path) -> (PathBuf, PathBuf) {
    let talker = dir.join("talker.xml");
    std::fs::write(
        &talker,
        r#"<?xml version="1.0" encoding="UTF-8"?>
<application name="shm_talker" version="1">
  <use library="ferroc_std"/>
  <part name="talker" host="localhost">
    <ros2 node="talker" domain="0">
      <publish port="main/clock/tick" topic="tick" type="std_msgs/msg/UInt64"/>
    </ros2>
    <thread name="main" period="20ms">
      <module name="clock" type="ferroc_std.Clock"/>
    </thread>
  </part>
</application>
"#,
    )
    .unwrap();
    let listener = dir.join("listener.xml");
    std::fs::write(
        &listener,
        r#"<?xml version="1.0" encoding="UTF-8"?>
<application name="shm_listener" version="1">
  <use library="ferroc_std"/>
  <part name="listener" host="localhost">
    <ros2 node="listener" domain="0">
      <subscribe port="main/echo/in/0" topic="/tick" type="std_msgs/msg/UInt64"/>
    </ros2>
    <thread name="main" period="20ms">
      <module name="echo" type="ferroc_std.Dump">
        <port name="in" dir="in" type="u64" count="1"/>
        <param name="label">tick</param>
      </module>
    </thread>
  </part>
</application>
"#,
    )
    .unwrap();
    (talker, listener)
}

/// A Zenoh configuration file `name` listening on `listen`, connecting to `connect`.
fn zenoh_config(dir: &Path, name: &str, listen: &str, connect: &[String]) -> PathBuf {
    let file = dir.join(name);
    let text = format!(
        "{{ connect: {{ endpoints: {} }},\n  listen: {{ endpoints: [\"{listen}\"] }} }}\n",
        serde_json::json!(connect)
    );
    std::fs::write(&file, text).unwrap();
    file
}

/// `ferroc run MODEL -q ARGS…` started by `command` (`ferroc` itself or a wrapper of
/// it), on the Zenoh configuration `config`.
fn run(mut command: Command, model: &Path, config: &Path, args: &[&str]) -> Command {
    command
        .args(["run", model.to_str().unwrap(), "-q"])
        .args(args)
        .env("FERROC_LOG_DIR", test_log_dir())
        .env("ZENOH_SESSION_CONFIG_URI", config)
        .current_dir(env!("CARGO_MANIFEST_DIR"));
    command
}

fn ferroc() -> PathBuf {
    PathBuf::from(env!("CARGO_BIN_EXE_ferroc"))
}

/// The two runs of a test: the listener listening on a port, the talker connecting.
struct Pair {
    dir: PathBuf,
    talker: PathBuf,
    listener: PathBuf,
}

impl Pair {
    /// The models and configurations in a scratch folder `name`; the runner (one for
    /// both models: the standard library with ROS 2 nodes) is built first, outside
    /// anything waited for, by a run of one cycle with nobody to connect to.
    fn new(name: &str) -> Pair {
        let dir = tempdir(name);
        let (talker, listener) = models(&dir);
        let nobody = zenoh_config(
            &dir,
            "nobody.json5",
            "tcp/127.0.0.1:0",
            &[format!("tcp/127.0.0.1:{}", free_port())],
        );
        let first = run(Command::new(ferroc()), &talker, &nobody, &["--lockstep"])
            .args(["--cycles", "1"])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&first.stderr);
        assert!(first.status.success(), "{err}");
        Pair {
            dir,
            talker,
            listener,
        }
    }

    /// Starts the listener on `port` (with `env` more in its environment): its process
    /// (the runner, which replaced `ferroc`) and its standard output, line by line.
    fn listener(&self, port: u16, env: &[(&str, &str)]) -> (Killed, Receiver<String>) {
        let listen = format!("tcp/127.0.0.1:{port}");
        let config = zenoh_config(&self.dir, "listen.json5", &listen, &[]);
        let mut command = run(Command::new(ferroc()), &self.listener, &config, &[]);
        command.args(["--for", "600s"]).envs(env.iter().copied());
        command.stdout(Stdio::piped()).stderr(Stdio::null());
        let mut child = command.spawn().expect("the listener starts");
        let out = lines(child.stdout.take().unwrap());
        (Killed(child), out)
    }

    /// Starts the talker connecting to `port`, through `wrapper` (`ferroc` itself when
    /// `None`): its process and its standard error, line by line.
    fn talker(&self, port: u16, wrapper: Option<Command>) -> (Killed, Receiver<String>) {
        let connect = [format!("tcp/127.0.0.1:{port}")];
        let config = zenoh_config(&self.dir, "connect.json5", "tcp/127.0.0.1:0", &connect);
        let command = wrapper.unwrap_or_else(|| Command::new(ferroc()));
        let mut command = run(command, &self.talker, &config, &["--for", "600s"]);
        command.stdout(Stdio::null()).stderr(Stdio::piped());
        let mut child = command.spawn().expect("the talker starts");
        let err = lines(child.stderr.take().unwrap());
        (Killed(child), err)
    }
}

/// Waits (bounded) until the listener printed `count` ticks, each a number; `talker` is
/// the talker's standard error, shown when they do not come.
fn ticks_arrive(out: &Receiver<String>, count: usize, talker: &Receiver<String>) {
    let deadline = Instant::now() + Duration::from_secs(120);
    let mut seen = 0;
    while seen < count {
        let left = deadline.saturating_duration_since(Instant::now());
        let line = (out.recv_timeout(left)).unwrap_or_else(|_| {
            let said: Vec<String> = talker.try_iter().collect();
            panic!("{seen} ticks arrived; the talker said {said:#?}")
        });
        let value = line.strip_prefix("tick: in/0 = ");
        assert!(
            value.is_some_and(|v| v.parse::<u64>().is_ok()),
            "not a tick: {line}"
        );
        seen += 1;
    }
}

#[test]
fn ros2_nodes_of_a_run_without_usable_shared_memory_publish_over_the_network_after_one_warning() {
    let pair = Pair::new("run_ros2_no_shm");
    // The computer's shared memory: silent.
    let (err, _) = ticks_from(&pair, None);
    assert!(err.iter().all(|l| !l.contains("warning")), "{err:#?}");

    for how in [NoShm::ReadOnly, NoShm::Missing] {
        let Some(wrapper) = no_shm::command(how, &ferroc()) else {
            return;
        };
        let (err, _) = ticks_from(&pair, Some(wrapper));
        let warnings: Vec<&String> = err.iter().filter(|l| l.contains("warning")).collect();
        assert_eq!(warnings.len(), 1, "{how:?}: {err:#?}");
        assert!(warnings[0].starts_with(WARNING), "{how:?}: {err:#?}");
        assert!(
            warnings[0].contains(
                "the ROS 2 nodes' messages to others on this computer travel over the network"
            ),
            "{how:?}: {err:#?}"
        );
        assert!(
            warnings[0].contains("in the file ZENOH_SESSION_CONFIG_URI names"),
            "{how:?}: {err:#?}"
        );
    }
}

/// A listener of its own (on a new port: every tick it prints is this talker's) and
/// the talker started through `wrapper`, until the listener printed 5 ticks: what the
/// talker wrote on standard error, and the listener's thread names (read meanwhile).
fn ticks_from(pair: &Pair, wrapper: Option<Command>) -> (Vec<String>, Vec<String>) {
    ticks_with(pair, wrapper, &[])
}

/// [`ticks_from`] with `env` more in the listener's environment.
fn ticks_with(
    pair: &Pair,
    wrapper: Option<Command>,
    env: &[(&str, &str)],
) -> (Vec<String>, Vec<String>) {
    let port = free_port();
    let (listener, out) = pair.listener(port, env);
    let (talker, err) = pair.talker(port, wrapper);
    ticks_arrive(&out, 5, &err);
    let names = threads(listener.0.id());
    drop((talker, listener));
    (err.iter().collect(), names)
}

/// The names of the threads of the process `pid`.
fn threads(pid: u32) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(format!("/proc/{pid}/task"))
        .unwrap()
        .filter_map(|t| std::fs::read_to_string(t.ok()?.path().join("comm")).ok())
        .map(|name| name.trim().to_string())
        .collect();
    names.sort();
    names
}

#[test]
fn the_runner_of_ros2_nodes_accepts_and_reads_on_zenoh_s_receive_runtime() {
    let pair = Pair::new("run_ros2_runtime");
    // ferroc's default: the listener accepted the talker's connection and reads it on
    // the receive runtime; no acceptor thread at all.
    let (_, names) = ticks_from(&pair, None);
    assert!(names.iter().any(|t| t.starts_with("rx-")), "{names:?}");
    assert!(
        !names.iter().any(|t| t.starts_with("acc-")),
        "an acceptor thread: {names:?}"
    );

    // The user's choice wins: Zenoh's own threads, with its acceptor.
    let (_, names) = ticks_with(&pair, None, &[("ZENOH_RUNTIME", "()")]);
    assert!(names.iter().any(|t| t == "acc-0"), "{names:?}");
}
