//! End-to-end tests of the `ferroc` command line on the real models in `models/`.

mod common;

use common::{ferroc, tempdir};
use std::path::Path;
use std::process::Command;

#[test]
fn every_bundled_model_checks_clean() {
    let (code, out, err) = ferroc(&["check", "models", "--format", "short"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(!out.contains("error["), "{out}");
    assert!(!out.contains("warning["), "{out}");
}

#[test]
fn a_broken_model_exits_1_with_location() {
    let dir = tempdir("broken");
    let model = dir.join("m.xml");
    std::fs::write(
        &model,
        "<application name=\"a\" version=\"1\">\n  <use library=\"ferroc_std\"/>\n  <part name=\"p\">\n    <thread name=\"t\" period=\"10ms\">\n      <module name=\"c\" type=\"ferroc_std.Constnt\"/>\n    </thread>\n  </part>\n</application>\n",
    )
    .unwrap();
    let (code, out, _) = ferroc(&["check", model.to_str().unwrap(), "--format", "short"]);
    assert_eq!(code, 1);
    assert!(out.contains("m.xml:5:30: error[M111]"), "{out}");
    assert!(out.contains("M111"), "{out}");
    let (_, human, _) = ferroc(&["check", model.to_str().unwrap(), "--color", "never"]);
    assert!(
        human.contains("help: did you mean `ferroc_std.Constant`?"),
        "{human}"
    );
}

#[test]
fn unreadable_input_and_bad_arguments_exit_2() {
    assert_eq!(ferroc(&["check", "no/such/model.xml"]).0, 2);
    assert_eq!(ferroc(&["check", "models", "--allow", "Q999"]).0, 2);
    assert_eq!(ferroc(&["explain", "Q999"]).0, 2);
    assert_eq!(ferroc(&["check"]).0, 2);
}

#[test]
fn deny_warnings_and_allow() {
    let dir = tempdir("deny");
    let model = dir.join("m.xml");
    // A part without threads is a warning (X101).
    std::fs::write(
        &model,
        "<application name=\"a\" version=\"1\">\n  <part name=\"idle\"/>\n</application>\n",
    )
    .unwrap();
    let m = model.to_str().unwrap();
    assert_eq!(ferroc(&["check", m]).0, 0);
    assert_eq!(ferroc(&["check", m, "--deny", "warnings"]).0, 1);
    let (code, out, _) = ferroc(&[
        "check", m, "--deny", "warnings", "--allow", "X101", "--format", "short",
    ]);
    assert_eq!((code, out.as_str()), (0, ""));
}

#[test]
fn explain_covers_every_code() {
    let (code, list, _) = ferroc(&["explain", "--list"]);
    assert_eq!(code, 0);
    let codes: Vec<&str> = list
        .lines()
        .map(|l| l.split_whitespace().next().unwrap())
        .collect();
    assert!(codes.len() >= 40, "{list}");
    for c in codes {
        let (code, text, _) = ferroc(&["explain", c]);
        assert_eq!(code, 0);
        assert!(
            text.contains("Fix") || text.contains("fix") || text.contains("Nothing to fix"),
            "{c}: {text}"
        );
    }
}

#[test]
fn machine_formats_are_well_formed() {
    let dir = tempdir("formats");
    let model = dir.join("m.xml");
    std::fs::write(&model, "<application name=\"a\" version=\"1\">\n  <part name=\"idle\" host=\"bad host\"/>\n</application>\n").unwrap();
    let m = model.to_str().unwrap();
    let (_, json, _) = ferroc(&["check", m, "--format", "json"]);
    let v: serde_json::Value = serde_json::from_str(&json).expect("json");
    assert_eq!(v["format_version"], 1);
    let d = &v["models"][0]["diagnostics"];
    assert!(d
        .as_array()
        .unwrap()
        .iter()
        .any(|d| d["code"] == "X102" && d["primary"]["location"]["line"] == 2));
    let (_, sarif, _) = ferroc(&["check", m, "--format", "sarif"]);
    let s: serde_json::Value = serde_json::from_str(&sarif).expect("sarif");
    assert_eq!(s["version"], "2.1.0");
    let result = &s["runs"][0]["results"][0];
    assert_eq!(result["ruleId"], "X101");
    assert_eq!(
        result["locations"][0]["physicalLocation"]["region"]["startLine"],
        2
    );
    let (_, junit, _) = ferroc(&["check", m, "--format", "junit"]);
    assert!(
        junit.contains("<testcase classname=") && junit.contains("<failure"),
        "{junit}"
    );
}

#[test]
fn hostile_include_is_a_diagnostic() {
    let dir = tempdir("hostile");
    let model = dir.join("m.xml");
    // Line 2 reaches the real /etc/passwd from any depth; line 3 names a file that
    // does not exist: both must be refused for where they point, not for whether
    // the target can be read.
    let up = "../".repeat(40);
    std::fs::write(
        &model,
        format!("<application name=\"a\" version=\"1\">\n  <include href=\"{up}etc/passwd\"/>\n  <include href=\"../no/such/fragment.xml\"/>\n</application>\n"),
    )
    .unwrap();
    let (code, out, _) = ferroc(&["check", model.to_str().unwrap(), "--format", "short"]);
    assert_eq!(code, 1);
    assert!(out.contains(":2:18: error[M113]"), "{out}");
    assert!(out.contains(":3:18: error[M113]"), "{out}");
    assert!(!out.contains("M115"), "{out}");
}

#[test]
fn schedule_orders_sense_before_control() {
    let (code, out, err) = ferroc(&["schedule", "models/crash_course.xml"]);
    assert_eq!(code, 0, "{err}");
    let position = |needle: &str| {
        out.find(needle)
            .unwrap_or_else(|| panic!("`{needle}` missing in:\n{out}"))
    };
    // The simulation senses first, the noise filters feed the controller's sense step,
    // the controller's control step comes before the simulation applies it.
    assert!(position("main_simulation (sense)") < position("add_noise_front (update)"));
    assert!(position("add_noise_front (update)") < position("controller (sense)"));
    assert!(position("controller (sense)") < position("controller (control)"));
    assert!(position("controller (control)") < position("main_simulation (control)"));
    assert!(out.contains("fragile_bot/main — every 40 ms"), "{out}");
    // A model with errors is refused with exit code 1.
    let (code, _, err) = ferroc(&[
        "schedule",
        "compiler/model/src/checks/t102_incompatible_types/fires.xml",
    ]);
    assert_eq!(code, 1, "{err}");
}

#[test]
fn run_executes_the_demo_for_a_number_of_cycles() {
    // Running freely: only what holds on a loaded machine. 30 cycles of the
    // application are 30 of its fastest container (40 ms); the display (100 ms) runs
    // until then, how often depends on the machine.
    let (code, stdout, stderr) = ferroc(&["run", "models/crash_course.xml", "--cycles", "30"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.contains("stopped (cycle limit reached)"), "{stderr}");
    assert!(stderr.contains("fragile_bot/main: 30 cycles, "), "{stderr}");
    assert!(
        stderr.contains("fragile_bot/main/simulation/display: "),
        "{stderr}"
    );
    assert!(
        stdout.contains("[ferroc crash course] robot 1: x="),
        "{stdout}"
    );
    // In lockstep, exactly: the display runs at 0, 100, …, 1100 ms (before 30 × 40 ms)
    // and reports the first robot turning in place at 1 s (its first look around).
    let (code, stdout, stderr) = ferroc(&[
        "run",
        "models/crash_course.xml",
        "--cycles",
        "30",
        "--lockstep",
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.contains("fragile_bot/main: 30 cycles, "), "{stderr}");
    assert!(
        stderr.contains("fragile_bot/main/simulation/display: 12 cycles, "),
        "{stderr}"
    );
    assert_eq!(
        stdout.lines().last(),
        Some(
            "[ferroc crash course] robot 1: x=+0.00 m y=+0.00 m heading=291.2° \
             front=150.0 cm rear=150.0 cm"
        ),
        "{stdout}"
    );
}

#[test]
fn run_refuses_a_rust_type_that_disagrees_with_its_manifest() {
    let dir = tempdir("run_mismatch");
    std::fs::create_dir_all(dir.join("models/etc")).unwrap();
    std::fs::create_dir_all(dir.join("components")).unwrap();
    for f in ["models/crash_course.xml", "models/etc/crash_course.xml"] {
        std::fs::copy(f, dir.join(f)).unwrap();
    }
    let manifest = std::fs::read_to_string("components/crash_course.lib.xml").unwrap();
    let changed = manifest.replace(
        r#"<param name="standard_deviation" type="f64" unit="m" min="0" max="1""#,
        r#"<param name="standard_deviation" type="f64" unit="m" min="0" max="2""#,
    );
    assert_ne!(manifest, changed);
    std::fs::write(dir.join("components/crash_course.lib.xml"), changed).unwrap();
    let model = dir.join("models/crash_course.xml");
    let (code, _, stderr) = ferroc(&["run", model.to_str().unwrap(), "--cycles", "1"]);
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.contains(
            "does not implement the interface its manifest declares for `crash_course.AddNoise`"
        ),
        "{stderr}"
    );
    assert!(
        stderr.contains(
            "parameter `standard_deviation`: the manifest says range `0..2`, the code `0..1`"
        ),
        "{stderr}"
    );
    assert!(
        stderr.contains("crash_course.lib.xml:"),
        "points at the manifest: {stderr}"
    );
}

#[test]
fn run_refuses_libraries_without_a_crate_and_models_with_errors() {
    // A library that names no crate for its module types.
    let dir = tempdir("not_built_in");
    std::fs::write(
        dir.join("phantom.lib.xml"),
        r#"<library name="phantom" version="0.1.0">
  <module-type name="Ghost" rust="phantom::Ghost"><out name="value" type="f64"/></module-type>
</library>"#,
    )
    .unwrap();
    let model = dir.join("haunted.xml");
    std::fs::write(
        &model,
        r#"<application name="haunted" version="1">
  <use library="phantom" manifest="phantom.lib.xml"/>
  <part name="p"><thread name="t" period="10ms"><module name="ghost" type="phantom.Ghost"/></thread></part>
</application>"#,
    )
    .unwrap();
    let (code, _, stderr) = ferroc(&["run", model.to_str().unwrap(), "--cycles", "1"]);
    assert_eq!(code, 1, "{stderr}");
    // The whole message: one finding at the manifest, nothing built or run.
    assert_eq!(
        stderr,
        format!(
            "{}:1:16: error: the library `phantom` has no `rust-crate`: ferroc cannot find the Rust code of its module types\n  \
             help: add rust-crate=\"PACKAGE\" to its <library>, naming the Cargo package (next to this manifest) whose `register` function registers them\n",
            shown(&dir.join("phantom.lib.xml"))
        )
    );
    let (code, _, stderr) = ferroc(&["run", "models/crash_course.xml", "--for", "soon"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("is not a duration"), "{stderr}");
    let (code, _, stderr) = ferroc(&["run", "models/crash_course.xml", "--param", "oops"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("write NAME=VALUE"), "{stderr}");
}

#[test]
fn run_stops_cleanly_on_sigterm() {
    use std::io::BufRead;
    let mut child = Command::new(env!("CARGO_BIN_EXE_ferroc"))
        .args(["run", "models/crash_course.xml"])
        .current_dir(Path::new(env!("CARGO_MANIFEST_DIR")))
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Wait until it runs (the first report line), then ask it to stop. `sh`'s built-in
    // kill: a minimal machine may have no kill binary.
    let mut first = String::new();
    std::io::BufReader::new(child.stdout.as_mut().unwrap())
        .read_line(&mut first)
        .unwrap();
    assert!(first.contains("robot 1"), "{first}");
    let status = Command::new("sh")
        .args(["-c", &format!("kill -TERM {}", child.id())])
        .status()
        .unwrap();
    assert!(status.success());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert!(stderr.contains("stopped (interrupted)"), "{stderr}");
}

const NETWORK: &str = "compiler/tests/behaviour_acceptance/clean.xml";

#[test]
fn graph_draws_stimulation_and_inhibition_apart_from_data() {
    let (code, out, err) = ferroc(&["graph", NETWORK]);
    assert_eq!(code, 0, "{err}");
    assert!(out.starts_with("digraph \"delivery_robot\" {"), "{out}");
    let edges: Vec<&str> = out.lines().filter(|l| l.contains(" -> ")).collect();
    let count = |style: &str| edges.iter().filter(|l| l.contains(style)).count();
    // Stimulation: operator → navigation's fusion, low_battery → dock (through group ports).
    assert_eq!(count("arrowhead=normal"), 2, "{out}");
    // Inhibition: mutual (2), emergency (2), dock → navigation's fusion (1).
    assert_eq!(count("arrowhead=tee"), 5, "{out}");
    // Activity and target rating into fusion channels: 3 + 2 channels, two edges each.
    assert_eq!(count("style=dashed"), 10, "{out}");
    // Inhibitions enter a behaviour's inhibition field from above, leaving an activity.
    assert!(
        edges
            .iter()
            .any(|l| l.contains(":a:s -> ") && l.contains(":i0:n [color=\"#c62828\"")),
        "{out}"
    );
    assert!(out.contains("label=\"navigation (iB2C group)\""), "{out}");
    assert!(out.contains("<i0> i0|<i1> i1}|go_to_goal"), "{out}");
}

#[test]
fn graph_svg_needs_graphviz_and_says_so() {
    // Without `dot` on PATH: a clear error, exit 2.
    let empty = tempdir("no_graphviz");
    let out = Command::new(env!("CARGO_BIN_EXE_ferroc"))
        .args(["graph", NETWORK, "--format", "svg"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("PATH", &empty)
        .output()
        .expect("ferroc runs");
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("Graphviz `dot` is not on PATH"), "{err}");
    assert!(out.stdout.is_empty());
}

#[test]
fn graph_svg_with_graphviz_draws_the_network() {
    if ferroc_testkit::command("dot").is_some() {
        let svg = tempdir("graphviz").join("net.svg");
        let (code, _, err) = ferroc(&[
            "graph",
            NETWORK,
            "--format",
            "svg",
            "-o",
            svg.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{err}");
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(
            text.contains("<svg") && text.contains("go_to_goal"),
            "{text}"
        );
    }
}

#[test]
fn graph_of_a_missing_model_exits_2() {
    assert_eq!(ferroc(&["graph", "no/such/model.xml"]).0, 2);
}

#[test]
fn the_b2_ring_runs_continuously_for_exactly_the_cycle_limit() {
    let (code, out, err) = ferroc(&["schedule", "models/control_loop.xml"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("bench/ring — continuously (cycles back to back)"),
        "{out}"
    );
    let (code, _, err) = ferroc(&["run", "models/control_loop.xml", "--cycles", "100000", "-q"]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("stopped (cycle limit reached)"), "{err}");
    assert!(
        err.contains("bench/ring: 100000 cycles, 0 overruns, load 100.0 %"),
        "{err}"
    );
}

#[test]
fn a_command_line_parameter_overrides_the_config_value_and_unknown_names_are_refused() {
    // front-noise is standard_deviation of the front noise (config value 0.01 m); 5 m is
    // beyond its declared range, so the override is visibly applied.
    let (code, _, err) = ferroc(&[
        "run",
        "models/crash_course.xml",
        "--cycles",
        "2",
        "-q",
        "--param",
        "front-noise=5m",
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("add_noise_front"), "{err}");
    assert!(err.contains("standard_deviation"), "{err}");
    let (code, _, err) = ferroc(&[
        "run",
        "models/crash_course.xml",
        "--cycles",
        "2",
        "-q",
        "--param",
        "front-noise=2cm",
    ]);
    assert_eq!(code, 0, "{err}");
    let (code, _, err) = ferroc(&[
        "run",
        "models/crash_course.xml",
        "--cycles",
        "2",
        "-q",
        "--param",
        "rear-noise=1cm",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("--param rear-noise: no parameter of models/crash_course.xml is declared with cmdline=\"rear-noise\""),
        "{err}"
    );
    assert!(err.contains("it accepts: front-noise"), "{err}");
}

#[test]
fn profile_switch_judges_a_model_by_another_framework_s_semantics() {
    let model = "compiler/tests/deadlock_examples/E17_self_call.xml";
    // Generic: the service runs in the caller's own container, which is busy calling.
    let (code, stdout, _) = ferroc(&["check", "--format", "short", model]);
    assert_eq!(code, 1, "{stdout}");
    assert!(
        stdout.contains("E17_self_call.xml:11:18: error[D101]"),
        "{stdout}"
    );
    // FINROC runs a call to a service of the same part inline in the caller's thread.
    let (code, stdout, stderr) =
        ferroc(&["check", "--format", "short", "--profile", "finroc", model]);
    assert_eq!(code, 0, "{stdout}{stderr}");
    assert!(!stdout.contains("D101"), "{stdout}");
    let (code, _, stderr) = ferroc(&["check", "--profile", "ros", model]);
    assert_eq!(code, 2, "an unknown profile is a usage error: {stderr}");
    assert!(
        stderr.contains("generic") && stderr.contains("finroc"),
        "{stderr}"
    );
}

/// A path as ferroc shows it: relative to the working directory when it lies below it.
fn shown(path: &Path) -> String {
    let cwd = std::env::current_dir().unwrap().canonicalize().unwrap();
    match path.strip_prefix(&cwd) {
        Ok(rel) => rel.display().to_string(),
        Err(_) => path.display().to_string(),
    }
}

/// Issue 27 item 16: `new library ferroc_runtime` (and `ferroc_host`) were accepted
/// and never built (this test failed so before the fix; only `ferroc_std` was
/// refused). Every crate of the workspace, read here from its manifests, is refused.
#[test]
fn new_library_refuses_the_name_of_every_crate_of_the_workspace() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let manifest = std::fs::read_to_string(root.join("Cargo.toml")).unwrap();
    let members = manifest.split("members = [").nth(1).unwrap();
    let members = &members[..members.find(']').unwrap()];
    let dir = common::tempdir("new_library_names");
    let mut names = Vec::new();
    for member in members.split(',').map(|m| m.trim().trim_matches('"')) {
        if member.is_empty() {
            continue;
        }
        let text = std::fs::read_to_string(root.join(member).join("Cargo.toml")).unwrap();
        let line = text.lines().find(|l| l.starts_with("name = ")).unwrap();
        names.push(line["name = ".len()..].trim_matches('"').replace('-', "_"));
    }
    assert!(names.len() >= 30, "{names:?}");
    for name in &names {
        let d = dir.join(name);
        let (code, _, err) = ferroc(&["new", "library", name, "--dir", d.to_str().unwrap()]);
        assert_eq!(code, 2, "{name}: {err}");
        assert!(
            err.contains("is the name of ferroc's own crate"),
            "{name}: {err}"
        );
        assert!(err.contains("help: choose another name"), "{name}: {err}");
        assert!(!d.exists(), "{name}");
    }
}
