//! `ferroc inspect --foxglove` with a Foxglove client we did not write: npm
//! `@foxglove/ws-protocol`'s FoxgloveClient (over `ws`), driven by
//! tests/foxglove/client.mjs, against `ferroc run models/nav_behaviours.xml --inspect`
//! on loopback. It receives the channel advertisements, subscribes and receives values
//! that change, lists the parameters, changes a speed limit (seen in the parameters and
//! in the next values) and has wrong values and a change without the token refused.
//!
//! Needs Node.js and the packages in FERROC_NODE_MODULES (default
//! target/ci-node/node_modules); `scripts/test` installs them, and without them the
//! test skips visibly (ferroc-testkit).

// A scenario reads as one story from start to end; the function-length rule is for
// the code under test.
#![allow(clippy::too_many_lines)]

mod common;

use ferroc_testkit::free_port;
use serde_json::{json, Value};
use std::io::{BufRead, BufReader, Write};
use std::path::PathBuf;
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{self, Receiver};
use std::time::{Duration, Instant};

/// A child process, killed when dropped, with its lines (stderr or stdout) arriving
/// on a channel.
struct Proc {
    child: Child,
    lines: Receiver<String>,
    stdin: Option<ChildStdin>,
}

impl Drop for Proc {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn spawn(mut command: Command, read_stdout: bool) -> Proc {
    let mut child = command
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("FERROC_LOG_DIR", common::test_log_dir())
        .stdin(Stdio::piped())
        .stdout(if read_stdout {
            Stdio::piped()
        } else {
            Stdio::null()
        })
        .stderr(if read_stdout {
            Stdio::inherit()
        } else {
            Stdio::piped()
        })
        .spawn()
        .expect("the program starts");
    let (tx, lines) = mpsc::channel();
    let stream: Box<dyn std::io::Read + Send> = match read_stdout {
        true => Box::new(child.stdout.take().unwrap()),
        false => Box::new(child.stderr.take().unwrap()),
    };
    std::thread::spawn(move || {
        for line in BufReader::new(stream).lines().map_while(Result::ok) {
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    let stdin = child.stdin.take();
    Proc {
        child,
        lines,
        stdin,
    }
}

/// Waits (bounded) for a line containing `marker`; returns it.
fn wait_line(p: &Proc, marker: &str, limit: Duration) -> String {
    let deadline = Instant::now() + limit;
    let mut seen = Vec::new();
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        match p.lines.recv_timeout(left) {
            Ok(line) if line.contains(marker) => return line,
            Ok(line) => seen.push(line),
            Err(_) => panic!("no line with `{marker}`; got:\n{}", seen.join("\n")),
        }
    }
}

/// The node_modules folder with @foxglove/ws-protocol and ws, or `None` after a
/// visible skip.
fn node_modules() -> Option<PathBuf> {
    ferroc_testkit::node_modules(&["@foxglove/ws-protocol", "ws"])
}

/// The Foxglove client's side: commands in, events out.
struct Foxglove {
    proc: Proc,
}

impl Foxglove {
    /// Connects; returns the client and the server's serverInfo (commands sent
    /// before the connection is open would be lost).
    fn connect(modules: &PathBuf, address: &str) -> (Foxglove, Value) {
        let mut node = Command::new("node");
        node.arg("tests/foxglove/client.mjs")
            .arg(format!("ws://{address}"))
            .env("FERROC_NODE_MODULES", modules);
        let fox = Foxglove {
            proc: spawn(node, true),
        };
        let info = fox.until("serverInfo", |e| e["ev"] == "serverInfo");
        (fox, info)
    }

    fn send(&mut self, command: Value) {
        let stdin = self.proc.stdin.as_mut().unwrap();
        writeln!(stdin, "{command}").unwrap();
        stdin.flush().unwrap();
    }

    /// The next event `keep` accepts (others are passed to `skipped`), bounded.
    fn until(&self, what: &str, mut keep: impl FnMut(&Value) -> bool) -> Value {
        let deadline = Instant::now() + Duration::from_secs(60);
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            let line = (self.proc.lines.recv_timeout(left))
                .unwrap_or_else(|_| panic!("the Foxglove client saw no {what}"));
            let event: Value = serde_json::from_str(&line)
                .unwrap_or_else(|e| panic!("the driver wrote `{line}`: {e}"));
            assert_ne!(
                event["ev"], "badMessage",
                "a message that is not JSON: {event}"
            );
            assert_ne!(event["ev"], "close", "the server closed the connection");
            if keep(&event) {
                return event;
            }
        }
    }

    fn parameters(&self, id: &str) -> Vec<Value> {
        let event = self.until(&format!("parameterValues {id}"), |e| {
            e["ev"] == "parameterValues" && e["id"] == id
        });
        event["parameters"].as_array().unwrap().clone()
    }
}

fn param<'a>(list: &'a [Value], name: &str) -> &'a Value {
    let p = list.iter().find(|p| p["name"] == name);
    &p.unwrap_or_else(|| panic!("no parameter {name} in {list:?}"))["value"]
}

/// Starts `ferroc inspect --foxglove` for the program on `inspect`; waits for it to
/// serve.
fn bridge(inspect: &str, token: Option<&str>) -> (Proc, String) {
    bridge_limited(inspect, token, "")
}

/// [`bridge`] with the limits `FERROC_INSPECT_LIMITS` sets (`""`: the defaults).
fn bridge_limited(inspect: &str, token: Option<&str>, limits: &str) -> (Proc, String) {
    let address = format!("127.0.0.1:{}", free_port());
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_ferroc"));
    cmd.args(["inspect", "--connect", inspect, "--foxglove", &address]);
    cmd.args(["--every", "50ms"]);
    cmd.env_remove("FERROC_INSPECT_TOKEN");
    cmd.env("FERROC_INSPECT_LIMITS", limits);
    if let Some(t) = token {
        cmd.args(["--token", t]);
    }
    let p = spawn(cmd, false);
    let line = wait_line(&p, "foxglove: serving", Duration::from_secs(120));
    assert!(line.contains(&format!("ws://{address}")), "{line}");
    (p, address)
}

#[test]
fn a_foxglove_client_sees_channels_and_values_and_sets_a_parameter() {
    let Some(modules) = node_modules() else {
        return;
    };
    let inspect = format!("127.0.0.1:{}", free_port());
    let mut run = Command::new(env!("CARGO_BIN_EXE_ferroc"));
    run.args(["run", "models/nav_behaviours.xml", "--for", "300s", "-q"]);
    run.args(["--inspect", &inspect]);
    let program = spawn(run, false);
    // The first run of the model builds its runner: minutes.
    let line = wait_line(&program, "token for changes: ", Duration::from_secs(600));
    let token = line.rsplit_once(": ").unwrap().1.trim().to_owned();

    let (first_bridge, address) = bridge(&inspect, Some(&token));
    // Changes need the token in the connection's URL (issue 27, item 1).
    let (mut fox, info) = Foxglove::connect(&modules, &format!("{address}/?token={token}"));
    assert!(
        info["capabilities"]
            .as_array()
            .unwrap()
            .contains(&json!("parameters")),
        "{info}"
    );

    // Channel advertisements: every port, and each part's figures.
    let mut advertised = std::collections::BTreeMap::new();
    let wanted = [
        "/robot/control/go_to_goal/linear",
        "/robot/control/avoid/activity",
        "/robot/control/sim/pose",
        "/robot/control/fusion/in/0/linear",
        "/robot/containers",
        "/robot/activities",
        "/robot/links",
    ];
    while !wanted.iter().all(|t| advertised.contains_key(*t)) {
        let event = fox.until("advertisements", |e| e["ev"] == "advertise");
        for c in event["channels"].as_array().unwrap() {
            advertised.insert(c["topic"].as_str().unwrap().to_owned(), c.clone());
        }
    }
    let linear = &advertised["/robot/control/go_to_goal/linear"];
    assert_eq!(
        (
            linear["encoding"].as_str(),
            linear["schemaEncoding"].as_str()
        ),
        (Some("json"), Some("jsonschema"))
    );
    let schema: Value = serde_json::from_str(linear["schema"].as_str().unwrap()).unwrap();
    assert_eq!(
        schema["properties"]["value"]["type"],
        json!(["number", "null"]),
        "{schema}"
    );
    // Pose2D is registered with its serde form: an object schema with its fields.
    let pose: Value = serde_json::from_str(
        advertised["/robot/control/sim/pose"]["schema"]
            .as_str()
            .unwrap(),
    )
    .unwrap();
    let value = &pose["properties"]["value"];
    assert_eq!(value["type"], "object", "{pose}");
    for field in ["x", "y", "theta"] {
        assert_eq!(
            value["properties"][field]["type"],
            json!(["number", "null"]),
            "{pose}"
        );
    }

    // Subscribed channels deliver JSON values that change; others deliver nothing.
    fox.send(
        json!({"op": "subscribe", "topics": ["/robot/control/sim/pose", "/robot/containers"]}),
    );
    let mut poses = std::collections::BTreeSet::new();
    let mut cycles = Vec::new();
    while poses.len() < 3 || cycles.len() < 3 {
        let m = fox.until("messages", |e| e["ev"] == "message");
        match m["topic"].as_str().unwrap() {
            "/robot/control/sim/pose" => {
                assert_eq!(m["data"]["port"], "robot/control/sim/pose", "{m}");
                assert!(m["data"]["value"]["x"].is_f64(), "{m}");
                poses.insert(m["data"]["value"].to_string());
            }
            "/robot/containers" => {
                let c = &m["data"]["containers"][0];
                assert_eq!(c["path"], "robot/control", "{m}");
                cycles.push(c["cycles"].as_u64().unwrap());
            }
            other => panic!("a message on {other}, which nobody subscribed to"),
        }
    }
    assert!(cycles.windows(2).all(|w| w[0] <= w[1]), "{cycles:?}");
    assert!(cycles.last() > cycles.first(), "{cycles:?}");

    // The parameters, named MODULE/PATH/NAME, with the model's values.
    fox.send(json!({"op": "getParameters", "names": [], "id": "all"}));
    let all = fox.parameters("all");
    let max_speed = "robot/control/go_to_goal/max_speed";
    assert_eq!(param(&all, max_speed), &json!(0.5));
    assert_eq!(param(&all, "robot/control/sim/beams"), &json!(72));
    assert_eq!(
        param(&all, "robot/control/follow_wall/side"),
        &json!("right")
    );

    // Names that are no parameter, or not even a key: errors, and the bridge serves on.
    let odd = ["", "a//b", "robot/**", "x#y", "robot/control/nothing/p"];
    fox.send(json!({"op": "getParameters", "names": odd, "id": "odd"}));
    for _ in odd {
        let status = fox.until("an error status", |e| e["ev"] == "status");
        assert_eq!(status["level"], 2, "{status}");
    }
    assert_eq!(fox.parameters("odd"), Vec::<Value>::new());

    // Values that do not check are refused: the client gets the value kept and an
    // error status saying why.
    for (id, value, why) in [
        ("text", json!("fast"), "keeps its value 0.5"),
        ("kind", json!(true), "keeps its value 0.5"),
        ("range", json!(5.0), "outside the allowed range"),
    ] {
        fox.send(json!({"op": "setParameters", "parameters": [{"name": max_speed, "value": value}], "id": id}));
        let status = fox.until("an error status", |e| e["ev"] == "status");
        assert_eq!(status["level"], 2, "{status}");
        assert!(
            status["message"].as_str().unwrap().contains(why),
            "{id}: {status}"
        );
        assert_eq!(param(&fox.parameters(id), max_speed), &json!(0.5), "{id}");
    }

    // A change that checks: applied, listed, and the next values obey it.
    fox.send(json!({"op": "setParameters", "parameters": [{"name": max_speed, "value": 0.05}], "id": "ok"}));
    assert_eq!(param(&fox.parameters("ok"), max_speed), &json!(0.05));
    fox.send(json!({"op": "getParameters", "names": [max_speed], "id": "after"}));
    assert_eq!(
        fox.parameters("after"),
        vec![json!({"name": max_speed, "value": 0.05})]
    );
    fox.send(json!({"op": "subscribe", "topics": ["/robot/control/go_to_goal/linear"]}));
    let mut slow_in_a_row = 0;
    while slow_in_a_row < 5 {
        let m = fox.until("slower speeds", |e| {
            e["ev"] == "message" && e["topic"] == "/robot/control/go_to_goal/linear"
        });
        let speed = m["data"]["value"].as_f64().unwrap();
        slow_in_a_row = if speed.abs() <= 0.05 + 1e-9 {
            slow_in_a_row + 1
        } else {
            0
        };
    }

    // A bridge without the token: reading works, changes are refused.
    let (_plain, plain_address) = bridge(&inspect, None);
    let (mut reader, _) = Foxglove::connect(&modules, &plain_address);
    reader.send(json!({"op": "setParameters", "parameters": [{"name": max_speed, "value": 0.3}], "id": "x"}));
    let status = reader.until("an error status", |e| e["ev"] == "status");
    assert!(
        status["message"]
            .as_str()
            .unwrap()
            .contains("not authorised"),
        "{status}"
    );
    assert_eq!(param(&reader.parameters("x"), max_speed), &json!(0.05));

    // The program ends: a bridge with subscribed channels says so and serves on.
    drop(program);
    wait_line(
        &first_bridge,
        "the program does not answer",
        Duration::from_secs(60),
    );
    let (_, info) = Foxglove::connect(&modules, &address);
    assert_eq!(info["ev"], "serverInfo");
}

#[test]
fn a_non_local_foxglove_address_needs_the_public_flag() {
    let (code, _, err) = common::ferroc(&["inspect", "--foxglove", "0.0.0.0:8765"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("not a loopback address") && err.contains("--foxglove-public"),
        "{err}"
    );
    let (code, _, err) = common::ferroc(&["inspect", "--foxglove", "nonsense"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("not an address HOST:PORT"), "{err}");
    // Allowed, the bridge goes on to look for the program (none here): exit 2 saying so.
    let (code, _, err) = common::ferroc(&[
        "inspect",
        "--connect",
        "127.0.0.1:1",
        "--foxglove",
        "0.0.0.0:8765",
        "--foxglove-public",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("cannot reach 127.0.0.1:1"), "{err}");
}

/// What tests/foxglove/raw.mjs saw: the refused upgrade's status and body, or that the
/// connection opened, or an error.
fn raw(modules: &PathBuf, url: &str, origin: Option<&str>) -> Value {
    let mut node = Command::new("node");
    node.arg("tests/foxglove/raw.mjs").arg(url);
    node.args(origin);
    let out = node
        .env("FERROC_NODE_MODULES", modules)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("node runs");
    let text = String::from_utf8_lossy(&out.stdout);
    serde_json::from_str(text.trim()).unwrap_or_else(|e| panic!("raw.mjs wrote `{text}`: {e}"))
}

fn float(list: &[Value], name: &str) -> f64 {
    param(list, name).as_f64().unwrap()
}

/// Issue 27, item 1: the bridge applied `setParameters` from any client, including a
/// web page of another site. Now a change needs the bridge's token in the connection's
/// URL, a wrong token and a foreign `Origin` are refused at the upgrade (403), and a
/// connection without the token reads but changes nothing. Failed before the fix (the
/// change without the token in the URL was applied, the foreign origin admitted).
#[test]
fn changes_need_the_token_in_the_url_and_other_sites_are_refused() {
    let Some(modules) = node_modules() else {
        return;
    };
    let program = common::inspected::start("tests/fixtures/inspect.xml");
    let (_bridge, address) = bridge(&program.address, Some(&program.token));
    let factor = "robot/main/scaled/factor";

    // No token in the URL: values and parameters are read, a change is refused.
    let (mut reader, _) = Foxglove::connect(&modules, &address);
    reader.send(
        json!({"op": "setParameters", "parameters": [{"name": factor, "value": 5.0}], "id": "no"}),
    );
    let status = reader.until("an error status", |e| e["ev"] == "status");
    let message = status["message"].as_str().unwrap();
    assert!(
        message.contains("not authorised") && message.contains("?token="),
        "{status}"
    );
    assert_eq!(float(&reader.parameters("no"), factor), 2.0);

    // The token in the URL: the change is made.
    let url = format!("{address}/?token={}", program.token);
    let (mut writer, _) = Foxglove::connect(&modules, &url);
    writer.send(
        json!({"op": "setParameters", "parameters": [{"name": factor, "value": 3.0}], "id": "yes"}),
    );
    assert_eq!(float(&writer.parameters("yes"), factor), 3.0);
    // The other connection still cannot.
    reader.send(json!({"op": "setParameters", "parameters": [{"name": factor, "value": 5.0}], "id": "again"}));
    assert_eq!(float(&reader.parameters("again"), factor), 3.0);

    // A wrong token: refused at the upgrade.
    let wrong = raw(
        &modules,
        &format!("ws://{address}/?token={}", "0".repeat(32)),
        None,
    );
    assert_eq!(wrong["status"], 403, "{wrong}");
    assert!(
        wrong["body"].as_str().unwrap().contains("not authorised"),
        "{wrong}"
    );
    // A page of another site: refused, with or without the token.
    for url in [format!("ws://{address}/"), format!("ws://{url}")] {
        let evil = raw(&modules, &url, Some("http://evil.example"));
        assert_eq!(evil["status"], 403, "{evil}");
        assert!(
            evil["body"].as_str().unwrap().contains("another site"),
            "{evil}"
        );
    }
    // A foreign host name (DNS rebinding): refused.
    let port = address.rsplit_once(':').unwrap().1;
    let rebound = raw(&modules, &format!("ws://localhost.:{port}/"), None);
    assert!(
        rebound["status"] == 403 || rebound.get("error").is_some(),
        "{rebound}"
    );
    // The Foxglove app's own origin, and clients that are no browser: admitted.
    let app = raw(
        &modules,
        &format!("ws://{address}/"),
        Some("https://app.foxglove.dev"),
    );
    assert_eq!(app["open"], true, "{app}");
    assert_eq!(app["protocol"], "foxglove.sdk.v1", "{app}");
    assert_eq!(
        raw(&modules, &format!("ws://{address}/"), None)["open"],
        true
    );
    // The value is the one the token's connection set.
    let (code, out, err) =
        common::ferroc(&["inspect", "--connect", &program.address, "--get", factor]);
    assert_eq!(
        (code, out.trim()),
        (0, "robot/main/scaled/factor = 3 (f64)"),
        "{err}"
    );
}

/// Issue 27, item 3: an idle client of the bridge was never dropped. The upgrade must
/// arrive in time (set small here); clients within it are served. Failed before the
/// fix (the idle connection stayed open).
#[test]
fn an_idle_client_of_the_bridge_is_dropped() {
    use std::io::Read;
    let Some(modules) = node_modules() else {
        return;
    };
    let program = common::inspected::start("tests/fixtures/inspect.xml");
    let (_bridge, address) = bridge_limited(&program.address, None, "header_ms=300");
    let mut idle = std::net::TcpStream::connect(&address).unwrap();
    idle.set_read_timeout(Some(Duration::from_secs(60)))
        .unwrap();
    let mut chunk = [0u8; 256];
    let closed = match idle.read(&mut chunk) {
        Ok(n) => n == 0,
        Err(e) => e.kind() == std::io::ErrorKind::ConnectionReset,
    };
    assert!(closed, "the idle connection stays open");
    let (_, info) = Foxglove::connect(&modules, &address);
    assert_eq!(info["ev"], "serverInfo");
}
