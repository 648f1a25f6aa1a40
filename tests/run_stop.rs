//! `ferroc run` always ends: by its limit, and on SIGTERM, also for a model whose queue
//! is never drained (`queue="1"` without `on-full`, which once meant `block` to the run
//! but `drop-oldest` to the checks, and hung the run after one cycle).

mod common;
use common::tempdir;
use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// Two modules of one container, the second reading only the latest value of a queued
/// input: nothing ever pops that queue. A Dump prints every cycle.
const UNDRAINED: &str = r#"<application name="undrained" version="1">
  <use library="ferroc_std"/>
  <part name="p">
    <thread name="t" period="10ms">
      <module name="c" type="ferroc_std.Constant"><param name="value">2</param></module>
      <module name="s" type="ferroc_std.Scale"/>
      <module name="show" type="ferroc_std.Dump">
        <port name="in" dir="in" type="f64" count="1"/>
      </module>
    </thread>
    <connect from="t/c/value" to="t/s/input" queue="1"/>
    <connect from="t/s/output" to="t/show/in/0"/>
  </part>
</application>
"#;

fn start(args: &[&str]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_ferroc"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("ferroc starts")
}

/// Waits for the child at most `limit` (a bound for a hang, not a speed figure:
/// the run itself takes a fraction of it); kills it and fails if it is still running.
fn wait_bounded(child: &mut Child, limit: Duration) -> (i32, String) {
    let deadline = Instant::now() + limit;
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            let mut err = String::new();
            std::io::Read::read_to_string(child.stderr.as_mut().unwrap(), &mut err).unwrap();
            return (status.code().unwrap_or(-1), err);
        }
        if Instant::now() >= deadline {
            let _ = child.kill();
            let _ = child.wait();
            panic!("ferroc run did not end within {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn a_queue_without_on_full_drops_the_oldest_and_the_run_reaches_its_limit() {
    let dir = tempdir("run_stop_limit");
    let model = dir.join("undrained.xml");
    std::fs::write(&model, UNDRAINED).unwrap();
    let mut child = start(&["run", model.to_str().unwrap(), "--cycles", "20", "-q"]);
    let (code, err) = wait_bounded(&mut child, Duration::from_secs(300));
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("stopped (cycle limit reached)"), "{err}");
    assert!(err.contains("p/t: 20 cycles"), "{err}");
}

#[test]
fn sigterm_stops_a_run_of_that_model() {
    let dir = tempdir("run_stop_signal");
    let model = dir.join("undrained.xml");
    std::fs::write(&model, UNDRAINED).unwrap();
    let mut child = start(&["run", model.to_str().unwrap(), "-q"]);
    // The first printed value says the run is under way (the handler is installed).
    let mut first = String::new();
    let mut out = BufReader::new(child.stdout.take().unwrap());
    out.read_line(&mut first).unwrap();
    assert!(first.contains("2"), "{first}");
    // Keep draining stdout so that the run never waits on a full pipe.
    std::thread::spawn(move || std::io::copy(&mut out, &mut std::io::sink()));
    let pid = child.id().to_string();
    let kill = Command::new("kill").args(["-TERM", &pid]).status().unwrap();
    assert!(kill.success());
    let (code, err) = wait_bounded(&mut child, Duration::from_secs(300));
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("stopped (interrupted)"), "{err}");
}

/// A fast container and a once-a-minute one: `--cycles` counts the application's cycles (the
/// fast one's), and `--for` does not wait for the slow container's next deadline.
const SLOW: &str = r#"<application name="slow" version="1">
  <use library="ferroc_std"/>
  <part name="p">
    <thread name="fast" period="10ms">
      <module name="c" type="ferroc_std.Constant"/>
    </thread>
    <thread name="slow" period="60s">
      <module name="s" type="ferroc_std.Constant"/>
    </thread>
  </part>
  <allow code="T110" reason="nothing to connect"/>
</application>
"#;

#[test]
fn cycles_count_the_application_and_a_slow_container_stops_with_it() {
    let dir = tempdir("run_stop_cycles");
    let model = dir.join("slow.xml");
    std::fs::write(&model, SLOW).unwrap();
    for args in [["--cycles", "5"], ["--for", "200ms"]] {
        let mut run = vec!["run", model.to_str().unwrap(), "-q"];
        run.extend(args);
        let mut child = start(&run);
        let (code, err) = wait_bounded(&mut child, Duration::from_secs(300));
        assert_eq!(code, 0, "{err}");
        // The slow container ran its first cycle and was stopped in its sleep.
        assert!(err.contains("p/slow: 1 cycles"), "{err}");
        if args[0] == "--cycles" {
            assert!(err.contains("p/fast: 5 cycles"), "{err}");
        }
    }
    // In lockstep exactly: the instants before 5 × 10 ms.
    let mut child = start(&[
        "run",
        model.to_str().unwrap(),
        "--lockstep",
        "--cycles",
        "5",
    ]);
    let (code, err) = wait_bounded(&mut child, Duration::from_secs(300));
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("p/fast: 5 cycles") && err.contains("p/slow: 1 cycles"),
        "{err}"
    );
}
