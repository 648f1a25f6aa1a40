//! The programs of a bundle over Zenoh when a peer dies (`kill -9`), on 127.0.0.1:
//! running freely the other program keeps running, reports the loss and the recovery
//! when the killed program is started again; in lockstep the other program ends with
//! a clear message and a non-zero exit, never a hang and never "cycle limit reached".
//! The model is `tests/fixtures/calls_between_parts.xml` (`asker` calls `server`).

mod common;

use common::{build_bundle, bundle_ok, tempdir};
use ferroc_testkit::free_address;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// The built bundle of the fixture (its binaries' folder).
fn programs(name: &str) -> PathBuf {
    let dir = tempdir(name);
    let model =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/calls_between_parts.xml");
    bundle_ok(&model, &dir.join("bundle"));
    build_bundle(&dir.join("bundle")).join("debug")
}

/// A started program and the lines of its standard error and output so far.
struct Program {
    child: Child,
    stderr: Arc<Mutex<Vec<String>>>,
    /// What its modules printed (the asker's Dump: one line per answer).
    stdout: Arc<Mutex<Vec<String>>>,
    /// The thread reading standard error; it ends when the program closed it.
    reader: Option<std::thread::JoinHandle<()>>,
}

/// The lines read from `pipe`, as they come, and the thread reading them (it ends when
/// the pipe is closed).
fn collect(
    pipe: impl std::io::Read + Send + 'static,
) -> (Arc<Mutex<Vec<String>>>, std::thread::JoinHandle<()>) {
    let lines = Arc::new(Mutex::new(Vec::new()));
    let into = Arc::clone(&lines);
    let reader = std::thread::spawn(move || {
        for line in BufReader::new(pipe).lines().map_while(Result::ok) {
            into.lock().unwrap().push(line);
        }
    });
    (lines, reader)
}

impl Program {
    fn start(bin: &Path, part: &str, addresses: &[(&str, &str)], args: &[&str]) -> Program {
        let mut command = Command::new(bin.join(format!("remote_calls-{part}")));
        command.args(args).arg("-q");
        for (peer, address) in addresses {
            command.args(["--peer", &format!("{peer}={address}")]);
            if peer == &part {
                command.args(["--listen", address]);
            }
        }
        let mut child = command
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let (stderr, reader) = collect(child.stderr.take().unwrap());
        // Its reader ends by itself when the program exits.
        let (stdout, _) = collect(child.stdout.take().unwrap());
        Program {
            child,
            stderr,
            stdout,
            reader: Some(reader),
        }
    }

    /// Everything the program wrote on standard error, once it exited (the reader
    /// thread has read to the end of the pipe).
    fn final_log(&mut self) -> String {
        if let Some(reader) = self.reader.take() {
            reader.join().unwrap();
        }
        self.log()
    }

    /// Waits (at most `limit`) until the asker printed an answer of the server: then
    /// the server's part is known to it, liveliness token included.
    fn answered(&self, limit: Duration) -> bool {
        let start = Instant::now();
        while start.elapsed() < limit {
            let lines = self.stdout.lock().unwrap();
            if lines.iter().any(|l| !l.ends_with("= 0")) {
                return true;
            }
            drop(lines);
            std::thread::sleep(Duration::from_millis(20));
        }
        false
    }

    fn said(&self, text: &str) -> bool {
        self.stderr.lock().unwrap().iter().any(|l| l.contains(text))
    }

    fn wait_for(&self, text: &str, limit: Duration) -> bool {
        let start = Instant::now();
        while start.elapsed() < limit {
            if self.said(text) {
                return true;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        false
    }

    fn log(&self) -> String {
        self.stderr.lock().unwrap().join("\n")
    }
}

impl Drop for Program {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

#[test]
fn running_freely_a_killed_peer_is_reported_and_so_is_its_return() {
    let bin = programs("bundle_zenoh_free");
    let (a, s) = (free_address(), free_address());
    let addresses = [("asker", a.as_str()), ("server", s.as_str())];
    let args = ["--for", "10min"];
    let asker = Program::start(&bin, "asker", &addresses, &args);
    let mut server = Program::start(&bin, "server", &addresses, &args);
    // Once the asker has an answer, it knows the server (and its liveliness token);
    // then kill -9.
    assert!(asker.answered(Duration::from_secs(60)), "{}", asker.log());
    server.child.kill().unwrap();
    let _ = server.child.wait();
    let limit = Duration::from_secs(30);
    assert!(
        asker.wait_for("link server → asker: part server gone", limit),
        "{}",
        asker.log()
    );
    // While it lasts, the log repeats it with the time since the loss (every 5 s).
    assert!(
        asker.wait_for("link server → asker: part server gone since ", limit),
        "{}",
        asker.log()
    );
    let _server = Program::start(&bin, "server", &addresses, &args);
    assert!(
        asker.wait_for("link server → asker: part server is back after", limit),
        "{}",
        asker.log()
    );
    drop(server);
    let mut asker = asker;
    assert!(
        asker.child.try_wait().unwrap().is_none(),
        "the asker keeps running"
    );
}

#[test]
fn in_lockstep_a_killed_peer_ends_the_other_program_with_an_error() {
    let bin = programs("bundle_zenoh_lockstep");
    let (a, s) = (free_address(), free_address());
    let addresses = [("asker", a.as_str()), ("server", s.as_str())];
    let args = ["--lockstep", "--cycles", "100000000"];
    let mut asker = Program::start(&bin, "asker", &addresses, &args);
    let mut server = Program::start(&bin, "server", &addresses, &args);
    // The two run in step once the asker has an answer; then kill -9 the server.
    assert!(asker.answered(Duration::from_secs(60)), "{}", asker.log());
    assert!(asker.child.try_wait().unwrap().is_none(), "{}", asker.log());
    server.child.kill().unwrap();
    let _ = server.child.wait();
    let start = Instant::now();
    let status = loop {
        if let Some(status) = asker.child.try_wait().unwrap() {
            break status;
        }
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "the asker hangs:\n{}",
            asker.log()
        );
        std::thread::sleep(Duration::from_millis(50));
    };
    let log = asker.final_log();
    assert_eq!(status.code(), Some(1), "{log}");
    assert!(
        log.contains("lockstep stopped: the part `server` is gone"),
        "{log}"
    );
    assert!(log.contains("stopped (failed)"), "{log}");
    assert!(!log.contains("cycle limit reached"), "{log}");
}

/// `models/rescue_robot.xml` (with its fragments and config files) in `dir`, its
/// manifests named by absolute path and its log files inside `dir`.
fn rescue_model(dir: &Path) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let copy = |from: &Path, to: &Path| {
        let text = std::fs::read_to_string(from).unwrap();
        let components = format!("manifest=\"{}/", root.join("components").display());
        let text = text
            .replace("manifest=\"../components/", &components)
            .replace("/var/", &format!("{}/var/", dir.display()));
        std::fs::create_dir_all(to.parent().unwrap()).unwrap();
        std::fs::write(to, text).unwrap();
    };
    for folder in ["fragments", "etc"] {
        for file in std::fs::read_dir(root.join("models").join(folder)).unwrap() {
            let path = file.unwrap().path();
            copy(&path, &dir.join(folder).join(path.file_name().unwrap()));
        }
    }
    let model = dir.join("rescue_robot.xml");
    copy(&root.join("models/rescue_robot.xml"), &model);
    model
}

/// The rescue model and its built programs' folder, made once for the tests here.
fn rescue_bundle() -> &'static (PathBuf, PathBuf) {
    static BUILT: std::sync::OnceLock<(PathBuf, PathBuf)> = std::sync::OnceLock::new();
    BUILT.get_or_init(|| {
        let dir = tempdir("bundle_zenoh_rescue");
        let model = rescue_model(&dir);
        bundle_ok(&model, &dir.join("bundle"));
        let bin = build_bundle(&dir.join("bundle")).join("debug");
        (model, bin)
    })
}

#[test]
fn a_station_without_its_robot_says_so_instead_of_printing_zeros() {
    let (_, bin) = rescue_bundle();
    let (robot, station) = (free_address(), free_address());
    let out = Command::new(bin.join("rescue_robot-station"))
        .args(["-q", "--for", "2500ms", "--listen", &station])
        .args(["--peer", &format!("robot={robot}")])
        .args(["--peer", &format!("station={station}")])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let status: Vec<&str> = stdout.lines().filter(|l| l.contains(" t=")).collect();
    assert!(!status.is_empty(), "{stdout}");
    for line in status {
        assert!(line.contains("no data from the robot yet"), "{line}");
        assert!(
            !line.contains("battery"),
            "no made-up battery value: {line}"
        );
    }
}

/// Two network namespaces joined by a veth pair, `10.77.0.1` and `10.77.0.2`: two
/// hosts on one machine. Removed again when dropped.
struct Hosts {
    names: [String; 2],
}

impl Hosts {
    /// The two hosts, or why this machine cannot make them (not root, no `ip`).
    fn new() -> Result<Hosts, String> {
        let id = std::process::id();
        let names = [format!("ferroc-{id}-a"), format!("ferroc-{id}-b")];
        let ip = |args: &[&str]| -> Result<(), String> {
            let out = Command::new("ip")
                .args(args)
                .output()
                .map_err(|e| format!("`ip` cannot run: {e}"))?;
            if out.status.success() {
                Ok(())
            } else {
                Err(format!(
                    "`ip {}` failed: {}",
                    args.join(" "),
                    String::from_utf8_lossy(&out.stderr).trim()
                ))
            }
        };
        ip(&["netns", "add", &names[0]])?;
        let hosts = Hosts { names };
        let [a, b] = &hosts.names;
        ip(&["netns", "add", b])?;
        let (va, vb) = (format!("fv{id}a"), format!("fv{id}b"));
        ip(&["link", "add", &va, "type", "veth", "peer", "name", &vb])?;
        for (ns, dev, address) in [(a, &va, "10.77.0.1/24"), (b, &vb, "10.77.0.2/24")] {
            ip(&["link", "set", dev, "netns", ns])?;
            ip(&["-n", ns, "addr", "add", address, "dev", dev])?;
            ip(&["-n", ns, "link", "set", dev, "up"])?;
            ip(&["-n", ns, "link", "set", "lo", "up"])?;
        }
        Ok(hosts)
    }
}

impl Drop for Hosts {
    fn drop(&mut self) {
        for name in &self.names {
            // Deleting a namespace deletes the veth end inside it, and so the pair.
            let _ = Command::new("ip").args(["netns", "del", name]).output();
        }
    }
}

#[test]
fn the_rescue_programs_on_two_hosts_in_network_namespaces_print_what_ferroc_run_prints() {
    let hosts = match Hosts::new() {
        Ok(hosts) => hosts,
        Err(why) => {
            ferroc_testkit::skip(&format!(
                "two hosts in network namespaces cannot be made here: {why}"
            ));
            return;
        }
    };
    let (model, bin) = rescue_bundle();
    let (robot, station) = ("10.77.0.1:47800", "10.77.0.2:47801");
    let start = |ns: &str, part: &str, listen: &str| {
        Command::new("ip")
            .args(["netns", "exec", ns])
            .arg(bin.join(format!("rescue_robot-{part}")))
            .args(["--lockstep", "-q", "--cycles", "100", "--listen", listen])
            .args(["--peer", &format!("robot={robot}")])
            .args(["--peer", &format!("station={station}")])
            .env("FERROC_LOG_DIR", common::test_log_dir())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap()
    };
    let mut children = [
        ("robot", start(&hosts.names[0], "robot", robot)),
        ("station", start(&hosts.names[1], "station", station)),
    ];
    // A bound for a hang (a peer that cannot be reached), not a speed figure.
    let deadline = Instant::now() + Duration::from_secs(600);
    while children
        .iter_mut()
        .any(|(_, c)| c.try_wait().unwrap().is_none())
    {
        if Instant::now() > deadline {
            for (_, c) in &mut children {
                let _ = c.kill();
            }
            panic!("the programs in the two namespaces did not finish");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let mut all = Vec::new();
    for (part, child) in children {
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "part {part}: {err}");
        assert!(err.contains("cycle limit reached"), "part {part}: {err}");
        all.extend(
            String::from_utf8_lossy(&out.stdout)
                .lines()
                .filter(|l| !l.starts_with("waiting for the part(s) "))
                .map(str::to_owned),
        );
    }
    let (code, run_out, run_err) = common::ferroc(&[
        "run",
        model.to_str().unwrap(),
        "--lockstep",
        "-q",
        "--cycles",
        "100",
    ]);
    assert_eq!(code, 0, "{run_err}");
    let mut expected: Vec<String> = run_out.lines().map(str::to_owned).collect();
    assert!(
        expected.iter().any(|l| l.contains("station alive")),
        "{run_out}"
    );
    all.sort_unstable();
    expected.sort_unstable();
    assert_eq!(all, expected, "the two hosts print what ferroc run prints");
    drop(hosts);
}
