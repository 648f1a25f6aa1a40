//! `ferroc inspect --serve`: the web page and its JSON API against real programs
//! (`ferroc run --inspect` on loopback). The API is asked with plain HTTP requests
//! written by hand (tests/common/web.rs); the page is loaded in a real browser — Debian's headless Chromium
//! driven by playwright-core from npm (tests/web/inspect_page.mjs) — which sees live
//! values change, checks the graph's geometry (it fits a 1400×900 window, no edge
//! labels intersect, a legend, labelled bars) and that values are short JSON, sets a
//! parameter with the token and sees its effect, and sees a change with a wrong token
//! refused. Its screenshots are printed. The graph's layout alone is checked in Node
//! (tests/web/layout.mjs). Hostile clients (idle, slow, too many):
//! tests/inspect_web_limits.rs.
//!
//! The browser test needs `node`, Debian's `chromium` and playwright-core in
//! FERROC_NODE_MODULES (default target/ci-node/node_modules); `scripts/test` installs
//! them, and without them the test skips visibly (ferroc-testkit).

mod common;

use common::inspected::{free_port, start, start_at, Running};
use common::web::{api, error, eventually, http, serve};
use serde_json::json;
use std::path::PathBuf;
use std::process::Command;
use std::time::{Duration, Instant};

#[test]
fn the_json_api_reads_and_changes_with_the_token_and_answers_malformed_requests_with_errors() {
    let program = start("tests/fixtures/inspect.xml");
    let web = serve(&program.address);

    let (status, tree) = api(&web, "GET /api/tree HTTP/1.1", "");
    assert_eq!(status, 200, "{tree}");
    let part = &tree["parts"][0];
    assert_eq!(
        (&part["app"], &part["part"]),
        (&json!("inspected"), &json!("robot"))
    );
    let modules: Vec<&str> = (part["tree"]["modules"].as_array().unwrap().iter())
        .map(|m| m["path"].as_str().unwrap())
        .collect();
    assert_eq!(
        modules,
        [
            "robot/main/speed",
            "robot/main/scaled",
            "robot/main/player_rate"
        ]
    );
    let (status, s) = api(
        &web,
        "GET /api/status?app=inspected&part=robot HTTP/1.1",
        "",
    );
    assert_eq!(status, 200, "{s}");
    assert_eq!(s["containers"][0]["path"], "robot/main");
    assert!(s["links"].as_array().unwrap().is_empty(), "{s}");
    assert_eq!(s["activities"], json!([]), "no behaviours here");
    // One process: no link travels between parts (tests/inspect_transport.rs).
    assert_eq!(s["transport"], json!({"links": [], "pool": null}), "{s}");
    eventually(&web, "robot/main/scaled/output", json!(8.0));
    let (_, p) = api(
        &web,
        "GET /api/param/robot/main/scaled/factor?app=inspected HTTP/1.1",
        "",
    );
    assert_eq!((&p["value"], &p["type"]), (&json!("2"), &json!("f64")));

    // Changes: the program's refusals come back as its own words (422).
    let set = "POST /api/param/robot/main/scaled/factor?app=inspected HTTP/1.1";
    let wrong = json!({"set": "5", "token": "0".repeat(32)}).to_string();
    assert!(error(&web, set, &wrong, 422).contains("not authorised"));
    let bad = json!({"set": "5 m", "token": program.token}).to_string();
    assert!(error(&web, set, &bad, 422).contains("keeps its value 2"));
    let good = json!({"set": "5", "token": program.token}).to_string();
    let (status, after) = api(&web, set, &good);
    assert_eq!((status, &after["value"]), (200, &json!("5")), "{after}");
    eventually(&web, "robot/main/scaled/output", json!(20.0));

    // Malformed requests: a 4xx JSON error each, and the server serves on.
    for (head, body, status, why) in [
        (
            "GET /api/values?app=inspected HTTP/1.1",
            "",
            400,
            "name 1 to",
        ),
        (
            "GET /api/values?paths=robot/** HTTP/1.1",
            "",
            400,
            "no empty parts or wildcards",
        ),
        (
            "GET /api/values?paths=robot//x HTTP/1.1",
            "",
            400,
            "not a path",
        ),
        (
            "GET /api/status?app=inspected HTTP/1.1",
            "",
            400,
            "name the part",
        ),
        (
            "GET /api/status?part=a/b HTTP/1.1",
            "",
            400,
            "cannot be the part's name",
        ),
        (
            "GET /api/tree?bogus=1 HTTP/1.1",
            "",
            400,
            "the query string",
        ),
        (
            "GET /api/tree?app=%FF HTTP/1.1",
            "",
            400,
            "cannot be the app's name",
        ),
        ("DELETE /api/tree HTTP/1.1", "", 405, "does not take DELETE"),
        (set, "not json", 400, "a change is the JSON"),
        (set, r#"{"set": "5"}"#, 400, "a change is the JSON"),
        (
            "POST /api/param/robot/main/scaled/factor HTTP/1.1",
            &good,
            400,
            "name the app",
        ),
        (
            "POST /api/edit?app=inspected&part=robot HTTP/1.1",
            "{",
            400,
            "an edit is a JSON",
        ),
        (
            "POST /api/edit?app=inspected HTTP/1.1",
            "{}",
            400,
            "name the part",
        ),
        (
            "GET /api/nothing HTTP/1.1",
            "",
            404,
            "is not a page or an API",
        ),
        (
            "GET /api/param/robot/main/scaled/nope?app=inspected HTTP/1.1",
            "",
            422,
            "has no parameter",
        ),
    ] {
        let e = error(&web, head, body, status);
        assert!(e.contains(why), "{head} {body}: {e}");
    }
    let huge = format!("{{\"set\": \"{}\", \"token\": \"x\"}}", "9".repeat(100_000));
    assert_eq!(http(&web.address, set, huge.as_bytes()).0, 413);
    // Another site's page in the same browser, or a rebound name: refused (403).
    let foreign = format!("{set}\r\nOrigin: http://evil.example");
    assert!(error(&web, &foreign, &good, 403).contains("another site"));
    let (status, text) = http(
        &web.address,
        "GET /api/tree HTTP/1.1\r\nHost: evil.example",
        b"",
    );
    assert_eq!(status, 403, "{text}");
    // An edit is forwarded to the program as it is; the program answers (here: refuses,
    // the token being wrong), not the web server.
    let (status, answer) = api(
        &web,
        "POST /api/edit?app=inspected&part=robot HTTP/1.1",
        r#"{"token": "00000000000000000000000000000000", "remove": "robot/main/speed"}"#,
    );
    assert_eq!(status, 422, "{answer}");
    assert!(!answer["error"].as_str().unwrap().is_empty(), "{answer}");
    // The page and its scripts are served.
    let (status, page) = http(&web.address, "GET / HTTP/1.1", b"");
    assert!(status == 200 && page.contains("<script type=\"module\" src=\"/app.js\">"));
    assert_eq!(http(&web.address, "GET /graph.js HTTP/1.1", b"").0, 200);

    // The program goes away: the API says so (502), and the web server runs on.
    let address = program.address.clone();
    drop(program);
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        let (status, json) = api(&web, "GET /api/tree HTTP/1.1", "");
        if status == 502 {
            let e = json["error"].as_str().unwrap();
            assert!(e.contains("no program answered"), "{json}");
            break;
        }
        assert!(Instant::now() < deadline, "still answered: {json}");
        std::thread::sleep(Duration::from_millis(200));
    }
    // A program serving that address again is found again.
    let _again = start_at("tests/fixtures/inspect.xml", &address);
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        let (status, json) = api(&web, "GET /api/tree HTTP/1.1", "");
        if status == 200 {
            assert_eq!(json["parts"][0]["app"], "inspected");
            break;
        }
        assert!(
            Instant::now() < deadline,
            "no answer after the restart: {json}"
        );
        std::thread::sleep(Duration::from_millis(200));
    }
}

#[test]
fn an_unreachable_program_is_reported_and_a_port_in_use_is_an_error() {
    // Nobody listens at the program's address: the page's API says so and retries.
    let nobody = format!("127.0.0.1:{}", free_port());
    let web = serve(&nobody);
    let e = error(&web, "GET /api/tree HTTP/1.1", "", 502);
    assert!(e.contains("cannot reach") && e.contains(&nobody), "{e}");
    // A second server on the same port: a clear error, exit 2.
    let (code, _, err) =
        common::ferroc(&["inspect", "--serve", &web.address, "--connect", &nobody]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("the port is in use"), "{err}");
    let (code, _, err) = common::ferroc(&["inspect", "--serve", "0.0.0.0:8790"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--serve-public"), "{err}");
    // Ctrl-C (SIGINT) stops the server cleanly: exit 0, the port free again.
    let mut web = web;
    let pid = web.child.id().to_string();
    let sent = Command::new("kill").args(["-INT", &pid]).status().unwrap();
    assert!(sent.success());
    let deadline = Instant::now() + Duration::from_secs(60);
    let status = loop {
        if let Some(status) = web.child.try_wait().unwrap() {
            break status;
        }
        assert!(Instant::now() < deadline, "still serving after Ctrl-C");
        std::thread::sleep(Duration::from_millis(50));
    };
    assert!(status.success(), "{status}");
    std::net::TcpListener::bind(&web.address).expect("the port is free again");
}

/// The node_modules with playwright-core and the Chromium it drives, or `None` after a
/// visible skip.
fn browser() -> Option<(PathBuf, PathBuf)> {
    let chromium = std::env::var("FERROC_CHROMIUM").unwrap_or_else(|_| "chromium".into());
    let chromium = ferroc_testkit::command(&chromium)?;
    Some((
        ferroc_testkit::node_modules(&["playwright-core"])?,
        chromium,
    ))
}

#[test]
fn the_page_shows_nav_behaviours_live_in_a_real_browser_and_sets_a_parameter() {
    let Some((node_modules, chromium)) = browser() else {
        return;
    };
    let program: Running = start("models/nav_behaviours.xml");
    let web = serve(&program.address);
    let shots = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("inspect_web");
    std::fs::create_dir_all(&shots).unwrap();
    let screenshot = shots.join("nav_behaviours.png");
    let _ = std::fs::remove_file(&screenshot);
    let _ = std::fs::remove_file(shots.join("nav_behaviours-graph.png"));
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/web/inspect_page.mjs");
    let out = Command::new("node")
        .arg(&script)
        .env("FERROC_NODE_MODULES", &node_modules)
        .env("FERROC_CHROMIUM", &chromium)
        .env("FERROC_PAGE_URL", format!("http://{}/", web.address))
        .env("FERROC_TOKEN", &program.token)
        .env("FERROC_SCREENSHOT", &screenshot)
        .env("FERROC_PROGRAM_PID", program.child.id().to_string())
        .output()
        .expect("node runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    println!("{stdout}");
    println!("screenshot of the page: {}", screenshot.display());
    assert!(
        out.status.success(),
        "the page test failed:\n{stdout}\n{stderr}"
    );
    for shot in [screenshot.clone(), shots.join("nav_behaviours-graph.png")] {
        let png = std::fs::read(&shot).expect("the screenshot was written");
        assert!(
            png.starts_with(b"\x89PNG\r\n\x1a\n") && png.len() > 10_000,
            "{} is not a screenshot",
            shot.display()
        );
    }
    // Every check of the script reported itself.
    for step in [
        "graph: 8 modules",
        "graph fits the window",
        "edge labels apart",
        "legend: stimulation, inhibition, meta, data, back, part, behaviour",
        "behaviour bars labelled",
        "zoom: actual size and back to fitted",
        "values as short JSON",
        "no ROS 2 lines",
        "a numeric port changed",
        "wrong token refused: not authorised",
        "operator/activity became 0.25",
        "unreachable shown",
    ] {
        assert!(stdout.contains(step), "missing `{step}` in:\n{stdout}");
    }
}

/// Runs `node tests/web/SCRIPT`, which must succeed and print `ok: STEP` for each step;
/// `false` after a visible skip when there is no `node`.
fn node_script(script: &str, steps: &[&str]) -> bool {
    let Some(node) = ferroc_testkit::command("node") else {
        return false;
    };
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/web")
        .join(script);
    let out = Command::new(node).arg(&path).output().expect("node runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    println!("{stdout}");
    assert!(
        out.status.success(),
        "{script} failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for step in steps {
        let line = format!("ok: {step}");
        assert!(stdout.contains(&line), "`{line}` missing in:\n{stdout}");
    }
    true
}

/// Issue 28, item 16: the page's graph layout (inspect/src/web/assets/layout.js) in
/// Node, without a browser (tests/web/layout.mjs): on nav_behaviours' graph, cycles, two
/// linked parts and a generated graph of 60 modules, no boxes overlap, no edge label
/// overlaps a box or another label, every data port has its label, no edge passes
/// through a box it does not connect, and parts stay apart; and the same checks find
/// the old drawing's faults put back into a layout. Before the fix, "linear" and
/// "angular" were drawn at the same place and data edges ended on a behaviour's
/// inhibition slot.
#[test]
fn the_graph_layout_keeps_boxes_labels_and_edges_apart() {
    node_script(
        "layout.mjs",
        &[
            "the checks find labels drawn over each other",
            "nav_behaviours:",
            "mutual inhibition and a self-loop:",
            "two parts linked both ways:",
            "60 generated modules:",
        ],
    );
}

/// Issue 28, item 16: values are shown as short JSON (tests/web/values.mjs): fractions
/// to 4 significant digits in shortest form (a pose's `0.7000000000000001` is `0.7`),
/// integers and short numbers as they are, long arrays cut with a count, still JSON.
#[test]
fn values_are_shown_as_short_json() {
    node_script(
        "values.mjs",
        &[
            "numbers shortened to 4 significant digits, integers and short numbers kept",
            "short JSON: {\"x\": -2.988, \"y\": 0.7, \"theta\": 0.7}",
        ],
    );
}
