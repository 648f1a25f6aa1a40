//! `ferroc inspect`'s errors in plain words (issue 28, items 13 and 14): no program to
//! reach, a bad --connect address, an --inspect address in use — none shows a source
//! path of Zenoh's crates — and a path the program does not have gets the nearest one
//! it has ("did you mean", the compiler's own).

mod common;

use common::ferroc;
use common::inspected::{free_port, start};

/// No dependency's internals: no Rust source location, no registry path, no Debug dump.
fn plain(text: &str) {
    for internal in [".rs:", "registry/src", "Os {", "Single(", "Timeout!"] {
        assert!(!text.contains(internal), "`{internal}` in:\n{text}");
    }
}

#[test]
fn no_program_and_a_bad_address_are_said_plainly() {
    let nobody = format!("127.0.0.1:{}", free_port());
    let (code, out, err) = ferroc(&["inspect", "--connect", &nobody, "--list"]);
    assert_eq!(code, 2, "{out}");
    assert!(
        err.contains(&format!("cannot reach {nobody}"))
            && err.contains("help: is the program running with --inspect"),
        "{err}"
    );
    plain(&err);
    for bad in ["256.1.1.1:80", "127.0.0.1", "[::1:5"] {
        let (code, _, err) = ferroc(&["inspect", "--connect", bad, "--get", "a/b"]);
        assert_eq!(code, 2, "{bad}");
        assert!(err.contains(&format!("--connect {bad}")), "{err}");
        plain(&err);
    }
}

#[test]
fn an_inspect_address_in_use_is_said_plainly() {
    let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let address = taken.local_addr().unwrap().to_string();
    let (code, _, err) = ferroc(&[
        "run",
        "tests/fixtures/inspect.xml",
        "--cycles",
        "10",
        "--inspect",
        &address,
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains(&format!(
            "cannot listen on tcp/{address}: address already in use"
        )),
        "{err}"
    );
    assert!(err.contains("help: another program serves there"), "{err}");
    plain(&err);
}

#[test]
fn a_path_the_program_does_not_have_gets_the_nearest_it_has() {
    let r = start("tests/fixtures/inspect.xml");
    let inspect = |args: &[&str]| {
        let mut all = vec!["inspect", "--connect", r.address.as_str()];
        all.extend_from_slice(args);
        ferroc(&all)
    };
    // A misspelt port, a misspelt parameter, a misspelt part.
    for (args, near) in [
        (
            &["--get", "robot/main/scaled/outptu"][..],
            "robot/main/scaled/output",
        ),
        (
            &["--get", "robot/main/scaled/factr"],
            "robot/main/scaled/factor",
        ),
        (
            &["--get", "robt/main/speed/value"],
            "robot/main/speed/value",
        ),
        (
            &["--watch", "robot/main/scald/output", "--count", "1"],
            "robot/main/scaled/output",
        ),
        (
            &[
                "--set",
                "robot/main/scaled/facter=3",
                "--token",
                r.token.as_str(),
            ],
            "robot/main/scaled/factor",
        ),
    ] {
        let (code, _, err) = inspect(args);
        assert_eq!(code, 1, "{args:?}: {err}");
        assert!(
            err.contains(&format!("help: did you mean `{near}`?")),
            "{args:?}: {err}"
        );
        plain(&err);
    }
    // Nothing near: no guess; a path that exists but is refused for another reason: none.
    let (code, _, err) = inspect(&["--get", "zzz/qqq/xxxxxxxxxxxxxxxxxxxxxx"]);
    assert_eq!(code, 1);
    assert!(!err.contains("did you mean"), "{err}");
    let (code, _, err) = inspect(&["--set", "robot/main/scaled/factor=abc", "--token", &r.token]);
    assert_eq!(code, 1);
    assert!(
        err.contains("is not a number") && !err.contains("did you mean"),
        "{err}"
    );
}
