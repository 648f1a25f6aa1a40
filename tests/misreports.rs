//! What ferroc says is true: a check that could not run is reported as such in every
//! machine format, a bad `--param` value is blamed on the argument, standard input is
//! read once, and control characters from a model never reach the terminal raw.

mod common;
use common::{ferroc, tempdir};
use std::io::Write;
use std::process::{Command, Stdio};

#[test]
fn sarif_says_when_ferroc_could_not_check() {
    let (code, out, _) = ferroc(&["check", "no/such/model.xml", "--format", "sarif"]);
    assert_eq!(code, 2);
    let doc: serde_json::Value = serde_json::from_str(&out).expect("a SARIF document");
    let invocation = &doc["runs"][0]["invocations"][0];
    assert_eq!(invocation["executionSuccessful"], false, "{out}");
    let note = &invocation["toolExecutionNotifications"][0];
    assert_eq!(note["level"], "error");
    assert!(
        note["message"]["text"]
            .as_str()
            .unwrap()
            .contains("no/such/model.xml"),
        "{out}"
    );
    // A check that ran: successful, whatever it found.
    let (code, out, _) = ferroc(&["check", "models/crash_course.xml", "--format", "sarif"]);
    assert_eq!(code, 0);
    let doc: serde_json::Value = serde_json::from_str(&out).unwrap();
    let invocation = &doc["runs"][0]["invocations"][0];
    assert_eq!(invocation["executionSuccessful"], true, "{out}");
    assert!(invocation.get("toolExecutionNotifications").is_none());
}

#[test]
fn junit_fails_a_test_case_when_ferroc_could_not_check() {
    let (code, out, _) = ferroc(&["check", "no/such/model.xml", "--format", "junit"]);
    assert_eq!(code, 2);
    assert!(
        out.contains(r#"<testsuites name="ferroc check" tests="1" failures="1">"#),
        "{out}"
    );
    assert!(
        out.contains(r#"type="tool-error">no/such/model.xml: no such file"#),
        "{out}"
    );
    let (code, out, _) = ferroc(&["check", "models/crash_course.xml", "--format", "junit"]);
    assert_eq!(code, 0);
    assert!(!out.contains("tool-error"), "{out}");
}

#[test]
fn a_bad_param_value_is_blamed_on_the_argument() {
    let args = ["run", "models/crash_course.xml", "--cycles", "1", "-q"];
    let (code, _, err) = ferroc(&[&args[..], &["--param", "front-noise=NaN"]].concat());
    assert_eq!(code, 1, "{err}");
    // (After the line saying that the runner is built, when it is.)
    assert!(
        err.lines()
            .any(|l| l
                .starts_with("models/crash_course.xml:57:95: error: --param front-noise=NaN: ")),
        "at the cmdline= that takes it: {err}"
    );
    assert!(err.contains("`NaN` is not a number of type `f64`"), "{err}");
    assert!(
        !err.contains("etc/crash_course.xml"),
        "not the config value it replaced: {err}"
    );
    // A good value runs.
    let (code, _, err) = ferroc(&[&args[..], &["--param", "front-noise=5cm"]].concat());
    assert_eq!(code, 0, "{err}");
}

/// `ferroc check ARGS` in `models/` with `input` on standard input: (code, stdout).
fn check_in_models(args: &[&str], input: &str) -> (Option<i32>, String) {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
    let mut child = Command::new(env!("CARGO_BIN_EXE_ferroc"))
        .arg("check")
        .args(args)
        .current_dir(dir) // the model's manifest and config paths are relative to models/
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(input.as_bytes())
        .unwrap();
    let out = child.wait_with_output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout) + String::from_utf8_lossy(&out.stderr);
    (out.status.code(), text.into_owned())
}

#[test]
fn a_model_on_standard_input_is_read_once() {
    let model = std::fs::read_to_string("models/crash_course.xml").unwrap();
    let (code, by_path) = check_in_models(&["crash_course.xml", "--format", "short"], "");
    assert_eq!(code, Some(0), "{by_path}");
    assert!(
        by_path.contains("crash_course.xml:106:23: note[T110]"),
        "{by_path}"
    );
    for name in ["-", "/dev/stdin"] {
        let (code, out) = check_in_models(&[name, "--format", "short"], &model);
        assert_eq!(code, Some(0), "{name}: {out}");
        assert_eq!(
            out,
            by_path.replace("crash_course.xml:", &format!("{name}:"))
        );
    }
}

#[test]
fn control_characters_in_names_are_escaped_in_every_format() {
    let dir = tempdir("misreports_escape");
    let path = dir.join("m.xml");
    std::fs::write(
        &path,
        r#"<application name="m" version="1">
  <use library="ferroc_std"/>
  <part name="p"><thread name="t" period="10ms">
    <module name="&#27;[2J&#27;[31mred&#x202E;" type="ferroc_std.Constant"/>
  </thread></part>
</application>
"#,
    )
    .unwrap();
    for format in ["human", "short", "junit"] {
        let (code, out, err) = ferroc(&["check", path.to_str().unwrap(), "--format", format]);
        assert_eq!(code, 1, "{err}");
        assert!(
            !out.contains('\u{1b}') && !out.contains('\u{202e}'),
            "{format}: {out:?}"
        );
        assert!(
            out.contains(r"`\u{1b}[2J\u{1b}[31mred\u{202e}` is not a valid name"),
            "{format}: {out}"
        );
    }
}
