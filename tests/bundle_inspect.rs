//! A bundle's part program serves inspection (`--inspect ADDR`): `ferroc inspect` reads
//! a live value from it and changes a parameter with the token it printed; a change
//! without the token, or in a unit the program cannot convert, is refused. The model
//! is `tests/fixtures/inspect.xml` (a constant, scaled by the parameter `factor`), one
//! part talking to no other: bundled with `--inspect`, without which its program links
//! no Zenoh and refuses `--inspect` with the help to bundle again.

mod common;

use common::Killed;

use common::{build_bundle, ferroc, tempdir};
use ferroc_testkit::free_address;
use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// `ferroc inspect --connect ADDRESS ARGS…`.
fn inspect(address: &str, args: &[&str]) -> (i32, String, String) {
    let mut all = vec!["inspect", "--connect", address];
    all.extend_from_slice(args);
    ferroc(&all)
}

/// Asks until the port's value is `want` (bounded: a change shows at the module's next
/// cycle).
fn eventually(address: &str, path: &str, want: f64) {
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        let (code, out, err) = inspect(address, &["--get", path, "--json"]);
        assert_eq!(code, 0, "{err}");
        let v: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
        if v["value"].as_f64() == Some(want) {
            return;
        }
        assert!(
            Instant::now() < deadline,
            "{path} stayed {v}, wanted {want}"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
}

#[test]
fn a_bundled_part_program_is_inspected_and_changed_with_its_token() {
    let dir = tempdir("bundle_inspect");
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/inspect.xml");
    let out = dir.join("bundle");
    let (code, _, err) = ferroc(&[
        "bundle",
        model.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--inspect",
    ]);
    assert_eq!(code, 0, "{err}");
    let bin = build_bundle(&out).join("debug").join("inspected-robot");

    // A non-local address needs --inspect-public: refused before anything runs.
    let refused = Command::new(&bin)
        .args(["--inspect", "0.0.0.0:47900", "--cycles", "1"])
        .output()
        .unwrap();
    assert_eq!(refused.status.code(), Some(2));
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(err.contains("--inspect-public"), "{err}");

    let address = free_address();
    let mut child = Command::new(&bin)
        .args(["--inspect", &address, "--for", "300s", "-q"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let stderr = child.stderr.take().unwrap();
    let _program = Killed(child);
    let (tx, lines) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    // The first lines may say other things (the run seed it chose); then the token.
    let line = std::iter::from_fn(|| lines.recv_timeout(Duration::from_secs(60)).ok())
        .find(|l| l.contains("serving "))
        .expect("the program prints its inspection token");
    assert!(
        line.contains(&format!(
            "serving ferroc/inspected/inspect/** on tcp/{address}"
        )),
        "{line}"
    );
    let token = line.rsplit_once("token for changes: ").unwrap().1.trim();

    // A live value, the tree of the part.
    eventually(&address, "robot/main/scaled/output", 8.0);
    let (code, out, err) = inspect(&address, &["--list"]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("application inspected, part robot"), "{out}");
    assert!(out.contains("param factor = 2 (f64)"), "{out}");
    // The model's side: where a module is declared, what feeds an input.
    assert!(
        out.contains("module robot/main/scaled : ferroc_std.Scale (plain) at inspect.xml:"),
        "{out}"
    );
    assert!(out.contains("← robot/main/speed/value"), "{out}");
    let (code, out, err) = inspect(&address, &["--get", "robot/main/scaled/input"]);
    assert_eq!(
        (code, out.trim()),
        (0, "robot/main/speed/value = 4.0"),
        "{err}"
    );

    // Refused: a wrong token, a unit (the parameter has none); nothing changes.
    let wrong = "0".repeat(32);
    let (code, _, err) = inspect(
        &address,
        &["--set", "robot/main/scaled/factor=5", "--token", &wrong],
    );
    assert_eq!(code, 1);
    assert!(err.contains("not authorised"), "{err}");
    let (code, _, err) = inspect(
        &address,
        &["--set", "robot/main/scaled/factor=5 m", "--token", token],
    );
    assert_eq!(code, 1);
    assert!(
        err.contains("has no unit") && err.contains("keeps its value 2"),
        "{err}"
    );
    eventually(&address, "robot/main/scaled/output", 8.0);

    // With the token: applied, and the next values show it.
    let (code, out, err) = inspect(
        &address,
        &["--set", "robot/main/scaled/factor=5", "--token", token],
    );
    assert_eq!(
        (code, out.trim()),
        (0, "robot/main/scaled/factor = 5 (f64)"),
        "{err}"
    );
    eventually(&address, "robot/main/scaled/output", 20.0);
}

#[test]
fn a_part_bundled_without_inspection_refuses_inspect_with_the_way_to_get_it() {
    let dir = tempdir("bundle_uninspected");
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/inspect.xml");
    let out = dir.join("bundle");
    let (code, _, err) = ferroc(&[
        "bundle",
        model.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let bin = build_bundle(&out).join("debug").join("inspected-robot");
    let refused = Command::new(&bin)
        .args(["--inspect", "--cycles", "1"])
        .output()
        .unwrap();
    assert_eq!(refused.status.code(), Some(2));
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(
        err.contains("error: --inspect: inspected-robot was bundled without inspection")
            && err.contains("help: bundle the model again with `ferroc bundle --inspect`"),
        "{err}"
    );
    // Without --inspect it runs as before.
    let ran = Command::new(&bin)
        .args(["--cycles", "2", "-q"])
        .output()
        .unwrap();
    assert!(
        ran.status.success(),
        "{}",
        String::from_utf8_lossy(&ran.stderr)
    );
}
