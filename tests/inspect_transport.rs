//! `ferroc inspect` says how each link between parts travels (issue 30, item 5): two
//! part programs of one bundle on this computer, with real shared memory (`/dev/shm`,
//! Zenoh's POSIX provider) and real sessions on loopback. The camera part sends an
//! image of 6,000 bytes (above the default threshold of 4 KiB: shared memory) and a
//! number (below it: network) to the viewer part; the inspected camera program reports
//! per link how its values went, and its pool's use, which the viewer's input keeps
//! above zero (it reads the latest image in place, so its buffer is held). Once the
//! viewer is killed (SIGKILL) while it holds that buffer, the pool says it came back.
//!
//! No assertion depends on speed: the test asks (bounded) until counts appear.

mod common;

use common::inspected::{free_port, lines, wait_for_line};
use common::{build_bundle, bundle_ok, ferroc, tempdir, test_log_dir};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

const IMAGE: &str = "camera/main/frame/out/0";
const RATE: &str = "camera/main/rate/value";

/// Kills the child when the test ends, however it ends.
struct Killed(Child);

impl Drop for Killed {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// The model: a 100×60 mono8 image and a number from the camera part to the viewer.
fn model(dir: &Path) -> PathBuf {
    let data = vec!["7"; 6000].join(",");
    let image = format!(
        r#"{{"width": 100, "height": 60, "encoding": "mono8", "step": 100, "data": [{data}]}}"#
    );
    let text = format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<application name="transport" version="1">
  <use library="ferroc_std"/>
  <part name="camera" host="localhost">
    <thread name="main" period="50ms">
      <module name="frame" type="ferroc_std.Const">
        <port name="out" dir="out" type="ferroc_std.Image" count="1"/>
        <param name="values">[{image}]</param>
      </module>
      <module name="rate" type="ferroc_std.Constant">
        <param name="value">25</param>
      </module>
    </thread>
  </part>
  <part name="viewer" host="localhost">
    <thread name="main" period="50ms">
      <module name="image" type="ferroc_std.Dump">
        <port name="in" dir="in" type="ferroc_std.Image" count="1"/>
      </module>
      <module name="rate" type="ferroc_std.Dump">
        <port name="in" dir="in" type="f64" count="1"/>
      </module>
    </thread>
  </part>
  <connect from="{IMAGE}" to="viewer/main/image/in/0"/>
  <connect from="{RATE}" to="viewer/main/rate/in/0"/>
</application>
"#
    );
    let file = dir.join("transport.xml");
    std::fs::write(&file, text).unwrap();
    file
}

/// Starts both programs (running freely), the camera inspected at `inspect`.
fn start(bin: &Path, inspect: &str) -> (Killed, Killed) {
    let addresses = [free_port(), free_port()].map(|p| format!("127.0.0.1:{p}"));
    let parts = ["camera", "viewer"];
    let program = |i: usize| {
        let mut command = Command::new(bin.join(format!("transport-{}", parts[i])));
        command
            .env("FERROC_LOG_DIR", test_log_dir())
            .args(["-q", "--for", "600s", "--listen", &addresses[i]])
            .stdout(Stdio::null())
            .stderr(Stdio::piped());
        for (peer, address) in parts.iter().zip(&addresses) {
            command.args(["--peer", &format!("{peer}={address}")]);
        }
        command
    };
    let mut camera = program(0);
    camera.args(["--inspect", inspect]);
    let mut camera = Killed(camera.spawn().unwrap());
    let viewer = Killed(program(1).spawn().unwrap());
    let stderr = lines(camera.0.stderr.take().unwrap());
    wait_for_line(&stderr, "token for changes: ", Duration::from_secs(120));
    (camera, viewer)
}

/// The camera's `--list --json` answer for its part, once both links carried values
/// and the pool holds a buffer (bounded).
fn settled(inspect: &str) -> serde_json::Value {
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        let (code, out, err) = ferroc(&["inspect", "--connect", inspect, "--list", "--json"]);
        assert_eq!(code, 0, "{err}");
        let all: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
        let transport = all["transport/camera"]["transport"].clone();
        let sent = |i: usize| {
            let l = &transport["links"][i];
            l["shared_memory"].as_u64().unwrap_or(0) + l["network"].as_u64().unwrap_or(0)
        };
        let held = transport["pool"]["used"].as_u64().unwrap_or(0);
        if sent(0) > 2 && sent(1) > 2 && held > 0 {
            return transport;
        }
        assert!(Instant::now() < deadline, "{out}");
        std::thread::sleep(Duration::from_millis(200));
    }
}

#[test]
fn the_inspector_shows_which_link_travels_by_shared_memory_and_the_pool_s_use() {
    let dir = tempdir("inspect_transport");
    let model = model(&dir);
    let (code, _, err) = ferroc(&["check", model.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    bundle_ok(&model, &dir.join("bundle"));
    let bin = build_bundle(&dir.join("bundle")).join("debug");
    let inspect = format!("127.0.0.1:{}", free_port());
    let (_camera, mut viewer) = start(&bin, &inspect);

    let transport = settled(&inspect);
    let links = transport["links"].as_array().unwrap();
    assert_eq!(links.len(), 2, "{transport}");
    let (image, rate) = (&links[0], &links[1]);
    assert_eq!(image["output"], IMAGE, "{transport}");
    assert_eq!(image["to_part"], "viewer", "{transport}");
    // The image: every value in shared memory.
    assert_eq!(image["by"], "shared memory", "{transport}");
    assert_eq!(image["network"], 0, "{transport}");
    // The number is below the threshold: every value over the network (silent case).
    assert_eq!(rate["output"], RATE, "{transport}");
    assert_eq!(rate["by"], "network", "{transport}");
    assert_eq!(rate["shared_memory"], 0, "{transport}");
    let pool = &transport["pool"];
    assert_eq!(
        pool["size"],
        64 * 1024 * 1024,
        "ferroc's default: {transport}"
    );
    assert_eq!(pool["threshold"], 4096, "{transport}");
    assert!(pool["used"].as_u64().unwrap() >= 6000, "{transport}");
    // No reader is gone: nothing came back, nothing said about it.
    assert_eq!(
        (&pool["reclaimed"], &pool["gone_held"]),
        (&0.into(), &0.into())
    );

    // The text says the same.
    let (code, out, err) = ferroc(&["inspect", "--connect", &inspect, "--list"]);
    assert_eq!(code, 0, "{err}");
    for line in [
        format!("  link out of {IMAGE} to viewer: shared memory ("),
        format!("  link out of {RATE} to viewer: network ("),
        "  shared memory pool: ".to_string(),
        " of 64.0 MiB in use, for values of 4.0 KiB and more".to_string(),
    ] {
        assert!(out.contains(&line), "`{line}` not in\n{out}");
    }
    assert!(!out.contains("readers that are gone"), "{out}");
    page_shows_transport(&inspect, false);

    // The viewer killed while its input held an image in place: the buffer comes back
    // to the camera's pool, and the inspector says so.
    viewer.0.kill().unwrap();
    let _ = viewer.0.wait();
    let pool = came_back(&inspect);
    assert_eq!(pool["gone_held"], 0, "{pool}");
    let (code, out, err) = ferroc(&["inspect", "--connect", &inspect, "--list"]);
    assert_eq!(code, 0, "{err}");
    let back = pool["reclaimed"].as_u64().unwrap();
    let plural = if back == 1 { "" } else { "s" };
    let line = format!("; of readers that are gone: {back} buffer{plural} back, 0 not yet\n");
    assert!(out.contains(&line), "`{line}` not in\n{out}");
    page_shows_transport(&inspect, true);
}

/// The camera's pool once a buffer came back from the killed viewer and none is
/// still counted for it (bounded).
fn came_back(inspect: &str) -> serde_json::Value {
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        let (code, out, err) = ferroc(&["inspect", "--connect", inspect, "--list", "--json"]);
        assert_eq!(code, 0, "{err}");
        let all: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
        let pool = all["transport/camera"]["transport"]["pool"].clone();
        let n = |k: &str| pool[k].as_u64().unwrap_or(0);
        if n("reclaimed") > 0 && n("gone_held") == 0 {
            return pool;
        }
        assert!(Instant::now() < deadline, "{pool}");
        std::thread::sleep(Duration::from_millis(200));
    }
}

/// The page in a real browser (skips visibly without Chromium and playwright-core);
/// `gone`: the viewer was killed, and the pool's row says what came back.
fn page_shows_transport(connect: &str, gone: bool) {
    let chromium = std::env::var("FERROC_CHROMIUM").unwrap_or_else(|_| "chromium".into());
    let Some(chromium) = ferroc_testkit::command(&chromium) else {
        return;
    };
    let Some(node_modules) = ferroc_testkit::node_modules(&["playwright-core"]) else {
        return;
    };
    let page = format!("127.0.0.1:{}", free_port());
    let mut web = Command::new(env!("CARGO_BIN_EXE_ferroc"));
    web.args(["inspect", "--serve", &page, "--connect", connect])
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    let mut web = Killed(web.spawn().expect("ferroc runs"));
    let stderr = lines(web.0.stderr.take().unwrap());
    wait_for_line(&stderr, "the page is on", Duration::from_secs(60));
    let script =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/web/inspect_transport_page.mjs");
    let out = Command::new("node")
        .arg(script)
        .env("FERROC_NODE_MODULES", &node_modules)
        .env("FERROC_CHROMIUM", &chromium)
        .env("FERROC_PAGE_URL", format!("http://{page}/"))
        .env("FERROC_READER_GONE", if gone { "1" } else { "0" })
        .output()
        .expect("node runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    println!("{stdout}");
    assert!(
        out.status.success(),
        "the page test failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for step in [
        "camera/main/frame/out/0 → viewer: shared memory",
        "camera/main/rate/value → viewer: network",
        "pool of camera",
    ] {
        assert!(stdout.contains(step), "missing `{step}` in:\n{stdout}");
    }
    let said = stdout.contains("of readers that are gone: ");
    assert_eq!(said, gone, "what came back from gone readers: {stdout}");
}
