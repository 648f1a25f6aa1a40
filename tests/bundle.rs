//! `ferroc bundle`: determinism, the resolved model, safety against hostile models and
//! output folders, and equivalence of a built bundle with `ferroc run`.

mod common;
use common::{build_bundle, bundle, ferroc};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A scratch folder of this file's own (below `bundle/`).
fn tempdir(name: &str) -> PathBuf {
    common::tempdir(&format!("bundle/{name}"))
}

/// Every file below `dir` (except a build's `target/`), by relative path.
fn read_tree(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    fn walk(root: &Path, dir: &Path, out: &mut BTreeMap<String, Vec<u8>>) {
        for e in std::fs::read_dir(dir).unwrap().flatten() {
            let path = e.path();
            if e.file_type().unwrap().is_dir() {
                if e.file_name() != "target" {
                    walk(root, &path, out);
                }
            } else {
                let rel = path
                    .strip_prefix(root)
                    .unwrap()
                    .to_string_lossy()
                    .into_owned();
                out.insert(rel, std::fs::read(&path).unwrap());
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(dir, dir, &mut out);
    out
}

/// A copy of the crash-course model, its config file and manifest, with `edit` applied
/// to the model text and `edit_manifest` to the manifest.
fn hostile_copy(name: &str, edit: &[(&str, &str)], edit_manifest: &[(&str, &str)]) -> PathBuf {
    let dir = tempdir(name);
    std::fs::create_dir_all(dir.join("models/etc")).unwrap();
    std::fs::create_dir_all(dir.join("components")).unwrap();
    std::fs::copy(
        "models/etc/crash_course.xml",
        dir.join("models/etc/crash_course.xml"),
    )
    .unwrap();
    let mut model = std::fs::read_to_string("models/crash_course.xml").unwrap();
    for (from, to) in edit {
        assert!(model.contains(from), "{from}");
        model = model.replace(from, to);
    }
    let mut manifest = std::fs::read_to_string("components/crash_course.lib.xml").unwrap();
    for (from, to) in edit_manifest {
        assert!(manifest.contains(from), "{from}");
        manifest = manifest.replace(from, to);
    }
    std::fs::write(dir.join("components/crash_course.lib.xml"), manifest).unwrap();
    std::fs::write(dir.join("models/crash_course.xml"), model).unwrap();
    dir.join("models/crash_course.xml")
}

#[test]
fn the_same_model_gives_a_byte_identical_bundle() {
    let dir = tempdir("determinism");
    let (a, b) = (dir.join("a"), dir.join("b"));
    let model = Path::new("models/crash_course.xml");
    assert_eq!(bundle(model, &a, &[]).0, 0);
    assert_eq!(bundle(model, &b, &[]).0, 0);
    let (ta, tb) = (read_tree(&a), read_tree(&b));
    for f in [
        "Cargo.toml",
        "manifest.json",
        "model/crash_course.xml",
        "model/libraries/crash_course.lib.xml",
        "parts/fragile_bot/Cargo.toml",
        "parts/fragile_bot/src/main.rs",
        "launch/localhost.sh",
        "systemd/crash_course-fragile_bot.service",
    ] {
        assert!(ta.contains_key(f), "{f} missing: {:?}", ta.keys());
    }
    assert!(ta == tb, "two bundles of one model differ");
    // Again into a bundle folder (--force): the same bytes.
    let (code, err) = bundle(model, &a, &["--force"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        read_tree(&a) == tb,
        "bundling again with --force changed files"
    );
}

#[test]
fn generated_code_is_wiring_with_the_concrete_types_and_formatted() {
    let dir = tempdir("wiring");
    let (code, err) = bundle(Path::new("models/crash_course.xml"), &dir.join("b"), &[]);
    assert_eq!(code, 0, "{err}");
    let main = std::fs::read_to_string(dir.join("b/parts/fragile_bot/src/main.rs")).unwrap();
    for expected in [
        "registry.register::<crash_course::MainSimulation>();",
        "registry.register::<crash_course::Controller>();",
        "const MAIN_SIMULATION: &str = \"fragile_bot/main/simulation/main_simulation\";",
        "param(\"seed\", Value::Int(4711))",
        "// crash_course.MainSimulation, crash_course.xml:43:9",
        "Conversion::linear(57.29577951308232, 0.0),",
        "schedule: Schedule::Periodic(Duration::from_millis(40)),",
        "(CONTROLLER.to_string(), StepKind::Control),",
        "supervise::supervise(app, &interrupted, &args.options())",
        // The simulation and the controller run in one thread container.
        "ConnectOptions::default().with_local(true),",
    ] {
        assert!(main.contains(expected), "`{expected}` missing in:\n{main}");
    }
    // The step order is the compiler's (sense steps before control steps).
    let sense = main
        .find("(CONTROLLER.to_string(), StepKind::Sense)")
        .unwrap();
    let control = main
        .find("(MAIN_SIMULATION.to_string(), StepKind::Control)")
        .unwrap();
    assert!(sense < control);
    // Only the types the part uses: no module type of ferroc_std; its recorders are
    // there for `--record`, with the outputs they may record.
    assert!(!main.contains("register::<ferroc_std"), "{main}");
    assert!(main.contains("use ferroc_std::recorder::{Recordable, Recorders};"));
    assert!(
        main.contains("Recordable::new(CONTROLLER, \"velocity\", \"f64\", \"fragile_bot/main\")"),
        "{main}"
    );
    // The library's recorded type with a serde form is recorded as `ferroc run
    // --record` records it (the pose), and nothing else of the library.
    assert_eq!(main.matches("register_serde").count(), 1, "{main}");
    assert!(
        main.contains("registry.register_serde::<crash_course::Pose2D>();"),
        "{main}"
    );
    if let Ok(out) = Command::new("rustfmt")
        .args(["--edition", "2021", "--check"])
        .arg(dir.join("b/parts/fragile_bot/src/main.rs"))
        .output()
    {
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stdout)
        );
    }
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("b/manifest.json")).unwrap()).unwrap();
    assert_eq!(manifest["tool"]["version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(manifest["parts"][0]["host"], "localhost");
    assert_eq!(
        manifest["binaries"][0],
        "target/release/crash_course-fragile_bot"
    );
    let sha = manifest["model"]["sha256"].as_str().unwrap();
    assert_eq!(sha.len(), 64);
    if let Ok(out) = Command::new("sha256sum")
        .arg("models/crash_course.xml")
        .output()
    {
        let expected = String::from_utf8_lossy(&out.stdout);
        assert!(expected.starts_with(sha), "{expected} vs {sha}");
    }
}

#[test]
fn the_resolved_model_checks_clean_and_plans_the_same() {
    let dir = tempdir("resolved");
    let (code, err) = bundle(Path::new("models/crash_course.xml"), &dir.join("b"), &[]);
    assert_eq!(code, 0, "{err}");
    let resolved = dir.join("b/model/crash_course.xml");
    let (code, out, err) = ferroc(&["check", resolved.to_str().unwrap()]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("0 error(s), 0 warning(s)"), "{out}");
    let original = plan_of(Path::new("models/crash_course.xml"));
    assert_eq!(plan_of(&resolved), original);
    assert!(original.contains("fragile_bot/main/control/controller"));
}

#[test]
fn the_resolved_multi_part_model_keeps_its_links() {
    let dir = tempdir("resolved_links");
    let model = Path::new("models/rescue_robot.xml");
    let (code, err) = bundle(model, &dir.join("b"), &[]);
    assert_eq!(code, 0, "{err}");
    let resolved = dir.join("b/model/rescue_robot.xml");
    let text = std::fs::read_to_string(&resolved).unwrap();
    assert!(text.contains(r#"sharing="periodic" period="2s""#), "{text}");
    assert!(text.contains(r#"min-interval="0.1s""#), "{text}");
    let (code, out, err) = ferroc(&["check", resolved.to_str().unwrap()]);
    assert_eq!(code, 0, "{out}{err}");
    let original = plan_of(model);
    assert_eq!(plan_of(&resolved), original);
    assert!(original.contains("Periodic { period: 2.0 }"), "{original}");
}

/// The plan of a model without source spans, connections sorted.
fn plan_of(model: &Path) -> String {
    use ferroc_compiler::load::{BuiltinLibrary, Options};
    let options = Options {
        builtins: vec![BuiltinLibrary {
            name: "ferroc_std".into(),
            text: include_str!("../components/ferroc_std.lib.xml").into(),
        }],
        ..Options::default()
    };
    let result = ferroc_compiler::check_model(model, &options, &Default::default()).unwrap();
    let app = result.app.as_ref().expect("an application");
    let (plan, unsupported) = ferroc_compiler::plan::plan(app, &result.libraries, &[]);
    assert!(unsupported.is_empty());
    let modules: Vec<String> = plan
        .modules
        .iter()
        .map(|m| {
            format!(
                "{} {} {} {:?} {:?}",
                m.path, m.type_name, m.rust, m.params, m.queues
            )
        })
        .collect();
    let mut connections: Vec<String> = plan
        .connections
        .iter()
        .map(|c| {
            let link = (c.link.as_ref()).map(|l| (&l.from_part, &l.to_part, &l.ty, l.sharing));
            format!(
                "{:?} -> {:?} {:?} ·{:?} +{:?} {link:?} local {}",
                c.from, c.to, c.select, c.scale, c.offset, c.local
            )
        })
        .collect();
    connections.sort();
    let threads: Vec<String> = plan
        .threads
        .iter()
        .map(|t| format!("{} {:?} {:?}", t.path, t.period, t.steps))
        .collect();
    format!("{modules:#?}\n{connections:#?}\n{threads:#?}")
}

#[test]
fn output_folders_that_are_links_or_not_empty_are_refused() {
    let dir = tempdir("outdirs");
    let model = Path::new("models/crash_course.xml");
    std::fs::create_dir_all(dir.join("real")).unwrap();
    std::os::unix::fs::symlink(dir.join("real"), dir.join("link")).unwrap();
    let (code, err) = bundle(model, &dir.join("link"), &[]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("is a symbolic link"), "{err}");
    let (code, err) = bundle(model, &dir.join("link"), &["--force"]);
    assert_eq!(code, 2, "a link is refused even with --force: {err}");
    assert!(read_tree(&dir.join("real")).is_empty());

    std::fs::write(dir.join("real/notes.txt"), "mine").unwrap();
    let (code, err) = bundle(model, &dir.join("real"), &[]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("is not empty") && err.contains("--force"),
        "{err}"
    );

    // A link planted inside a bundle folder is not followed, even with --force.
    std::fs::create_dir_all(dir.join("outside")).unwrap();
    std::os::unix::fs::symlink(dir.join("outside"), dir.join("real/parts")).unwrap();
    let (code, err) = bundle(model, &dir.join("real"), &["--force"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("symbolic link"), "{err}");
    assert!(
        read_tree(&dir.join("outside")).is_empty(),
        "wrote through the link"
    );
    assert_eq!(
        std::fs::read_to_string(dir.join("real/notes.txt")).unwrap(),
        "mine"
    );

    let (code, err) = bundle(model, &dir.join("x"), &["--prefix", "../etc"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--prefix"), "{err}");
}

#[test]
fn hostile_models_cannot_inject_code_or_escape_the_folder() {
    // A string that tries to end the literal and run code.
    let evil = r#"x"); std::process::exit(7); ("\ &#10;fn x() {} &#x202E;"#;
    let model = hostile_copy(
        "hostile_string",
        &[(
            "<param name=\"window_title\">ferroc crash course</param>",
            &format!("<param name=\"window_title\">{evil}</param>"),
        )],
        &[],
    );
    let out = model.parent().unwrap().join("out");
    let (code, err) = bundle(&model, &out, &[]);
    assert_eq!(code, 0, "{err}");
    let main = std::fs::read_to_string(out.join("parts/fragile_bot/src/main.rs")).unwrap();
    assert!(
        main.contains(
            r#"Value::Text("x\"); std::process::exit(7); (\"\\ \nfn x() {} \u{202e}".to_string())"#
        ),
        "{main}"
    );
    // rustfmt parses it: the literal did not end early.
    if let Ok(o) = Command::new("rustfmt")
        .args(["--edition", "2021", "--check"])
        .arg(out.join("parts/fragile_bot/src/main.rs"))
        .output()
    {
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }

    // A manifest whose `rust=` tries to smuggle statements into the registry.
    let model = hostile_copy(
        "hostile_rust_path",
        &[],
        &[(
            r#"rust="crash_course::Visualization""#,
            r#"rust="crash_course::Visualization>(); std::process::exit(7); registry.register::<crash_course::Visualization""#,
        )],
    );
    let out = model.parent().unwrap().join("out");
    let (code, err) = bundle(&model, &out, &[]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("which is not a Rust path"), "{err}");
    assert!(!out.exists(), "nothing is written for a refused model");

    // Names that are not identifiers and hosts that are paths stop at the check.
    for (name, edit) in [
        (
            "hostile_name",
            ("name=\"controller\"", "name=\"controller&quot;)\""),
        ),
        ("hostile_host", ("host=\"localhost\"", "host=\"../../etc\"")),
    ] {
        let model = hostile_copy(name, &[edit], &[]);
        let out = model.parent().unwrap().join("out");
        let (code, err) = bundle(&model, &out, &[]);
        assert_eq!(code, 1, "{name}: {err}");
        assert!(!out.exists(), "{name}");
    }

    // A crate name that is not a Cargo package name.
    let model = hostile_copy(
        "hostile_crate",
        &[],
        &[(r#"rust-crate="crash-course""#, r#"rust-crate="../../x""#)],
    );
    let (code, err) = bundle(&model, &model.parent().unwrap().join("out"), &[]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("is not a Cargo package name"), "{err}");
}

#[test]
fn models_the_runtime_cannot_run_are_refused() {
    let dir = tempdir("unsupported");
    // Writing into one element of an input: the runtime cannot realise it yet.
    let model = dir.join("element_write.xml");
    let ring = Path::new(env!("CARGO_MANIFEST_DIR")).join("components/ring.lib.xml");
    std::fs::write(
        &model,
        format!(
            r#"<application name="element_write" version="1">
  <use library="ring" manifest="{}"/>
  <part name="p">
    <thread name="t" period="10ms">
      <module name="a" type="ring.Stage"/>
      <module name="b" type="ring.Stage"/>
      <connect from="a/output[1]" to="b/input[0]"/>
    </thread>
  </part>
</application>
"#,
            ring.display()
        ),
    )
    .unwrap();
    let (code, err) = bundle(&model, &dir.join("b"), &[]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("element_write.xml:7:39: error: writing into one element of an input (`to=\"port[i]\"`) is not supported"),
        "{err}"
    );
    assert!(!dir.join("b").exists());
    let (code, err) = bundle(Path::new("models/missing.xml"), &dir.join("c"), &[]);
    assert_eq!(code, 2, "{err}");
}

/// Builds the bundle of the crash course and runs it next to `ferroc run`: the same
/// module logic, wired by generated code instead of at run time, gives the same output.
///
/// The simulation advances by a fixed step and the visualisation reads noise-free
/// values, so what it prints depends only on how many cycles of the 40 ms container ran
/// before each 100 ms display cycle. With 20 cycles the control loop ends at 0.8 s and
/// the display's last report (at 1.0 s) shows the final pose, which is exact. (The
/// report at 0 s may or may not come before the first simulation step.)
#[test]
fn a_built_bundle_behaves_like_ferroc_run() {
    let dir = tempdir("equivalence");
    let out = dir.join("b");
    let (code, err) = bundle(Path::new("models/crash_course.xml"), &out, &[]);
    assert_eq!(code, 0, "{err}");
    let target = build_bundle(&out);
    let program = target.join("debug/crash_course-fragile_bot");
    // In lockstep, so that the comparison does not depend on thread timing.
    let bundled = Command::new(&program)
        .args(["--cycles", "50", "--lockstep", "-q"])
        .output()
        .unwrap();
    let (code, run_out, run_err) = ferroc(&[
        "run",
        "models/crash_course.xml",
        "--cycles",
        "50",
        "--lockstep",
        "-q",
    ]);
    assert_eq!(code, 0, "{run_err}");
    let (b_out, b_err) = (
        String::from_utf8_lossy(&bundled.stdout),
        String::from_utf8_lossy(&bundled.stderr),
    );
    assert!(bundled.status.success(), "{b_err}");
    let last = |s: &str| s.lines().last().unwrap_or("").to_string();
    assert_eq!(
        last(&b_out),
        last(&run_out),
        "bundle:\n{b_out}\nrun:\n{run_out}"
    );
    // 50 cycles into its first look around: still turning in place, to the right.
    assert!(
        last(&b_out).contains("robot 1: x=+0.00 m y=+0.00 m heading=291.2°"),
        "{b_out}"
    );
    // The same summary: reason and cycles per thread container.
    let summary = |s: &str| -> Vec<String> {
        s.lines()
            .filter(|l| l.starts_with("stopped") || l.contains(" cycles, "))
            .map(|l| {
                let l = l.split(" after ").next().unwrap_or(l);
                l.split(" cycles, ").next().unwrap_or(l).to_string()
            })
            .collect()
    };
    assert_eq!(summary(&b_err), summary(&run_err), "{b_err}\n{run_err}");
    assert!(
        summary(&b_err).contains(&"  fragile_bot/main: 50".to_string()),
        "{b_err}"
    );

    let (code, help) = {
        let o = Command::new(&program).arg("--help").output().unwrap();
        (
            o.status.code(),
            String::from_utf8_lossy(&o.stdout).into_owned(),
        )
    };
    assert_eq!(code, Some(0));
    assert!(
        help.contains("--cycles N") && help.contains("fragile_bot"),
        "{help}"
    );
    let o = Command::new(&program)
        .arg("--cycles")
        .arg("x")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
}

/// Issue 27 item 9: `bundle -o -` made a folder named `-`, and a bundle that ran out
/// of disk left a half-written folder (this test failed so before the fix). Now `-` is
/// refused, and the bundle is written beside its folder and renamed into place at the
/// end: a full disk leaves nothing behind.
#[test]
fn a_bundle_is_written_whole_or_not_at_all() {
    let dir = tempdir("whole");
    let model = Path::new("models/crash_course.xml");
    let (code, err) = bundle(model, Path::new("-"), &[]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("`-o -` cannot name the bundle") && err.contains("help:"),
        "{err}"
    );
    assert!(!Path::new(env!("CARGO_MANIFEST_DIR")).join("-").exists());
    // Into a new folder and an empty one: whole, and nothing beside it.
    let (code, err) = bundle(model, &dir.join("new"), &[]);
    assert_eq!(code, 0, "{err}");
    std::fs::create_dir_all(dir.join("empty")).unwrap();
    let (code, err) = bundle(model, &dir.join("empty"), &[]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(read_tree(&dir.join("new")), read_tree(&dir.join("empty")));
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name())
        .collect();
    assert_eq!(left.len(), 2, "{left:?}");
    // A disk too small for the bundle.
    let small = dir.join("small");
    let Some(_disk) = common::SmallDisk::mount(&small, "16k") else {
        return;
    };
    let (code, err) = bundle(model, &small.join("bundle"), &[]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("No space left on device"), "{err}");
    let left: Vec<_> = std::fs::read_dir(&small)
        .unwrap()
        .flatten()
        .map(|e| e.file_name())
        .collect();
    assert!(left.is_empty(), "a full disk left {left:?}");
}
