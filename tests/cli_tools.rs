//! The command line of a mature tool (issue 28, item 12): completion scripts that
//! their shells parse, manual pages that render, `--color` on every command (and
//! NO_COLOR), and `ferroc run --format json` holding the run's figures.

mod common;
use common::{ferroc, tempdir};
use std::process::Command;

/// Parses `script` with `shell`'s own syntax check (`-n`), if that shell is here.
fn parses(shell: &str, script: &std::path::Path) {
    let Some(program) = ferroc_testkit::command(shell) else {
        return; // the skip is said by the testkit
    };
    let out = Command::new(program)
        .arg("-n")
        .arg(script)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{shell} -n {}: {}",
        script.display(),
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn completion_scripts_parse_in_their_shells_and_know_the_commands() {
    let dir = tempdir("cli_tools_completions");
    for (shell, file) in [
        ("bash", "ferroc.bash"),
        ("zsh", "_ferroc"),
        ("fish", "ferroc.fish"),
    ] {
        let (code, script, err) = ferroc(&["completions", shell]);
        assert_eq!(code, 0, "{err}");
        for word in ["check", "inspect", "completions", "--lockstep", "--color"] {
            assert!(script.contains(word), "{shell}: no `{word}`");
        }
        std::fs::write(dir.join(file), &script).unwrap();
        parses(shell, &dir.join(file));
    }
    let (code, _, err) = ferroc(&["completions", "tcsh"]);
    assert_eq!(code, 2);
    assert!(err.contains("bash") && err.contains("zsh"), "{err}");
}

#[test]
fn manual_pages_are_roff_that_renders_for_ferroc_and_every_command() {
    let (code, page, err) = ferroc(&["man"]);
    assert_eq!(code, 0, "{err}");
    assert!(page.contains(".TH ferroc 1"), "{page}");
    for section in [".SH NAME", ".SH SYNOPSIS", ".SH DESCRIPTION", ".SH OPTIONS"] {
        assert!(page.contains(section), "no {section}");
    }
    let (code, page, err) = ferroc(&["man", "import", "finroc"]);
    assert_eq!(code, 0, "{err}");
    assert!(page.contains(".TH ferroc-import-finroc 1"), "{page}");
    let (code, _, err) = ferroc(&["man", "improt"]);
    assert_eq!(code, 2);
    assert!(err.contains("did you mean `import`?"), "{err}");

    let dir = tempdir("cli_tools_man");
    let (code, _, err) = ferroc(&["man", "--dir", dir.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let written = std::fs::read_dir(&dir).unwrap().count();
    for page in [
        "ferroc.1",
        "ferroc-check.1",
        "ferroc-run.1",
        "ferroc-import-finroc.1",
    ] {
        assert!(dir.join(page).is_file(), "no {page} among {written}");
    }
    assert!(
        err.contains(&format!("wrote {written} manual pages")),
        "{err}"
    );
    let Some(groff) = ferroc_testkit::command("groff") else {
        return;
    };
    let out = Command::new(groff)
        .args(["-man", "-Tutf8", "-ww", "-z"])
        .arg(dir.join("ferroc-run.1"))
        .output()
        .unwrap();
    assert!(out.status.success(), "groff failed");
    assert!(
        out.stderr.is_empty(),
        "groff warns: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A model with one error (a misspelt type), for coloured findings.
fn model_with_an_error() -> std::path::PathBuf {
    let dir = tempdir("cli_tools_color");
    let model = dir.join("m.xml");
    std::fs::write(
        &model,
        "<application name=\"a\" version=\"1\">\n  <use library=\"ferroc_std\"/>\n  <part name=\"p\">\n    <thread name=\"t\" period=\"10ms\">\n      <module name=\"c\" type=\"ferroc_std.Constnt\"/>\n    </thread>\n  </part>\n</application>\n",
    )
    .unwrap();
    model
}

const ESC: char = '\u{1b}';

#[test]
fn color_always_colours_never_does_not_and_auto_follows_the_terminal_and_no_color() {
    let model = model_with_an_error();
    let model = model.to_str().unwrap();
    let (_, out, _) = ferroc(&["check", model, "--color", "always"]);
    assert!(out.contains(ESC), "{out}");
    let (_, out, _) = ferroc(&["check", model, "--color", "never"]);
    assert!(!out.contains(ESC) && out.contains("did you mean"), "{out}");
    // Into a pipe, auto does not colour.
    let (_, out, _) = ferroc(&["check", model]);
    assert!(!out.contains(ESC), "{out}");
    // The flag stands before or after the command, and help and usage errors obey it.
    for args in [
        &["--color", "always", "check", "--help"][..],
        &["check", "--help", "--color=always"],
    ] {
        let (code, out, _) = ferroc(args);
        assert_eq!(code, 0);
        assert!(out.contains(ESC), "{args:?}");
    }
    let (_, out, _) = ferroc(&["check", "--help", "--color", "never"]);
    assert!(!out.contains(ESC));
    let (code, _, err) = ferroc(&["check", "--no-such-flag", "--color", "always"]);
    assert_eq!(code, 2);
    assert!(err.contains(ESC), "{err}");
    // On a terminal (script(1) gives one), auto colours unless NO_COLOR is set.
    let Some(script) = ferroc_testkit::command("script") else {
        return;
    };
    let on_terminal = |no_color: Option<&str>| {
        let line = format!("{} check {model}", env!("CARGO_BIN_EXE_ferroc"));
        let mut cmd = Command::new(&script);
        cmd.args(["-qec", &line, "/dev/null"]);
        match no_color {
            Some(v) => cmd.env("NO_COLOR", v),
            None => cmd.env_remove("NO_COLOR"),
        };
        String::from_utf8_lossy(&cmd.output().unwrap().stdout).into_owned()
    };
    assert!(on_terminal(None).contains(ESC));
    assert!(!on_terminal(Some("1")).contains(ESC));
}

#[test]
fn run_format_json_is_one_versioned_line_with_the_runs_figures() {
    let (code, out, err) = ferroc(&[
        "run",
        "tests/fixtures/inspect.xml",
        "--lockstep",
        "--cycles",
        "25",
        "--seed",
        "42",
        "--format",
        "json",
    ]);
    assert_eq!(code, 0, "{err}");
    let last = out.lines().last().unwrap_or_default();
    let doc: serde_json::Value = serde_json::from_str(last).unwrap();
    assert_eq!(doc["version"], 1);
    assert_eq!(doc["application"], "inspected");
    assert_eq!(doc["seed"], 42);
    assert_eq!(doc["lockstep"], true);
    assert_eq!(doc["reason"], "cycle limit reached");
    assert_eq!(doc["exit_code"], 0);
    assert_eq!(doc["data_lost"], serde_json::json!([]));
    assert_eq!(doc["panics"], serde_json::json!([]));
    let containers = doc["containers"].as_array().unwrap();
    assert_eq!(containers.len(), 1, "{doc}");
    assert_eq!(containers[0]["path"], "robot/main");
    assert_eq!(containers[0]["cycles"], 25);
    assert_eq!(containers[0]["overruns"], 0);
    assert!(doc["seconds"].as_f64().is_some_and(|s| s >= 0.0));
    // The human summary is still on standard error, with the same figures.
    assert!(err.contains("robot/main: 25 cycles, 0 overruns"), "{err}");
    // Without --format json, standard output has no summary.
    let (_, out, _) = ferroc(&[
        "run",
        "tests/fixtures/inspect.xml",
        "--lockstep",
        "--cycles",
        "5",
    ]);
    assert!(!out.contains("\"version\""), "{out}");
}
