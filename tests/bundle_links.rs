//! Bundles of the models whose parts are linked (`models/rescue_robot.xml`: robot ↔
//! station; `models/warehouse_fleet.xml`: three AGVs ↔ fleet server). Each part is a
//! program of its own; the programs talk over TCP on this computer. Run in lockstep,
//! together they print exactly what `ferroc run --lockstep` prints for the whole model:
//! the same lines, and each program's lines in the same order.
//!
//! The single-part models are checked the same way: one program, the same lines in
//! the same order. The models run as they are, with their log and report files moved
//! into a scratch folder.

mod common;

use common::{build_bundle, bundle_ok, ferroc, tempdir};
use ferroc_testkit::free_address;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// A copy of `models/NAME.xml` (and its fragments and config files) in `dir` whose files live in `dir`.
fn copy_model(name: &str, dir: &Path) -> PathBuf {
    copy_model_from(&format!("models/{name}.xml"), name, dir)
}

/// A copy of the model `source` (relative to the project) as `dir/NAME.xml`.
fn copy_model_from(source: &str, name: &str, dir: &Path) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scratch = format!("{}/var/", dir.display());
    let copy = |from: &Path, to: &Path| {
        let text = std::fs::read_to_string(from).unwrap();
        let components = format!("manifest=\"{}/", root.join("components").display());
        let text = text
            .replace("manifest=\"../components/", &components)
            .replace("/var/", &scratch);
        std::fs::create_dir_all(to.parent().unwrap()).unwrap();
        std::fs::write(to, text).unwrap();
    };
    for folder in ["fragments", "etc"] {
        for file in std::fs::read_dir(root.join("models").join(folder)).unwrap() {
            let path = file.unwrap().path();
            copy(&path, &dir.join(folder).join(path.file_name().unwrap()));
        }
    }
    let model = dir.join(format!("{name}.xml"));
    copy(&root.join(source), &model);
    model
}

/// Runs every part's program in lockstep for `cycles`; their standard outputs.
fn run_parts(bin: &Path, application: &str, parts: &[&str], cycles: u32) -> Vec<String> {
    let addresses: Vec<String> = parts.iter().map(|_| free_address()).collect();
    let mut children = Vec::new();
    for (part, listen) in parts.iter().zip(&addresses) {
        let mut command = Command::new(bin.join(format!("{application}-{part}")));
        command.env("FERROC_LOG_DIR", common::test_log_dir());
        command.args(["--lockstep", "-q", "--cycles", &cycles.to_string()]);
        command.args(["--listen", listen]);
        for (peer, address) in parts.iter().zip(&addresses) {
            command.args(["--peer", &format!("{peer}={address}")]);
        }
        let child = command
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        children.push(child);
    }
    // A bound for a hang, not a speed figure (a loaded machine may take minutes).
    let deadline = Instant::now() + Duration::from_secs(600);
    while children.iter_mut().any(|c| c.try_wait().unwrap().is_none()) {
        assert!(Instant::now() < deadline, "the programs did not finish");
        std::thread::sleep(Duration::from_millis(20));
    }
    children
        .into_iter()
        .zip(parts)
        .map(|(child, part)| {
            let out = child.wait_with_output().unwrap();
            let err = String::from_utf8_lossy(&out.stderr);
            assert!(out.status.success(), "part {part}: {err}");
            assert!(err.contains("cycle limit reached"), "part {part}: {err}");
            // A program that waited more than 5 s of wall time for a slow peer says so;
            // that note depends on the machine's speed, not on the application.
            String::from_utf8_lossy(&out.stdout)
                .lines()
                .filter(|l| !l.starts_with("waiting for the part(s) "))
                .map(|l| format!("{l}\n"))
                .collect()
        })
        .collect()
}

/// Whether `part` appears in `whole` in order (other lines may come between).
fn in_order(part: &[&str], whole: &[&str]) -> bool {
    let mut rest = whole.iter();
    part.iter().all(|line| rest.any(|l| l == line))
}

fn programs_match_ferroc_run(name: &str, parts: &[&str], cycles: u32, must_print: &str) {
    let source = format!("models/{name}.xml");
    programs_match(&source, name, parts, cycles, must_print);
}

fn programs_match(source: &str, name: &str, parts: &[&str], cycles: u32, must_print: &str) {
    let dir = tempdir(&format!("bundle_links_{name}"));
    let model = copy_model_from(source, name, &dir);
    let out = dir.join("bundle");
    bundle_ok(&model, &out);
    let target = build_bundle(&out);
    let outputs = run_parts(&target.join("debug"), name, parts, cycles);

    let cycles = cycles.to_string();
    let args = [
        "run",
        model.to_str().unwrap(),
        "--lockstep",
        "-q",
        "--cycles",
        &cycles,
    ];
    let (code, run_out, run_err) = ferroc(&args);
    assert_eq!(code, 0, "{run_err}");
    assert!(run_out.contains(must_print), "{run_out}");
    let whole: Vec<&str> = run_out.lines().collect();
    let mut all: Vec<&str> = outputs.iter().flat_map(|o| o.lines()).collect();
    for (part, output) in parts.iter().zip(&outputs) {
        let lines: Vec<&str> = output.lines().collect();
        assert!(
            in_order(&lines, &whole),
            "part {part} printed, in this order:\n{output}"
        );
    }
    let mut expected = whole.clone();
    all.sort_unstable();
    expected.sort_unstable();
    assert_eq!(
        all, expected,
        "the programs together print what ferroc run prints"
    );
}

#[test]
fn the_rescue_robot_and_its_station_as_two_programs() {
    let dir = tempdir("bundle_links_rescue_source");
    let model = copy_model("rescue_robot", &dir);
    bundle_ok(&model, &dir.join("b"));
    let robot = std::fs::read_to_string(dir.join("b/parts/robot/src/main.rs")).unwrap();
    for line in [
        "builder.link_out(&LINK_4, (DETECTOR, \"victims\"), Conversion::default())?;",
        "builder.link_in(&LINK_9, (PLANNER, \"goal\"), ConnectOptions::default())?;",
        "registry.register_serde::<rescue_components::VictimList>();",
        "const PARTS: &[(&str, &str)] = &[(\"robot\", \"robot-pc:47800\"), (\"station\", \"base-pc:47801\")];",
    ] {
        assert!(robot.contains(line), "{line} missing in\n{robot}");
    }
    // 100 cycles of the application: 2.5 s of model time (the 25 ms driver runs 100).
    programs_match_ferroc_run("rescue_robot", &["robot", "station"], 100, "station alive");
}

#[test]
fn the_warehouse_fleet_as_four_programs() {
    let parts = ["agv_1", "agv_2", "agv_3", "fleet_server"];
    programs_match_ferroc_run("warehouse_fleet", &parts, 60, "Hamburg DC2 - AGV fleet");
}

#[test]
fn every_single_part_model_as_one_program() {
    for (name, part, cycles, must_print) in [
        (
            "crash_course",
            "fragile_bot",
            60,
            "[ferroc crash course] robot 1",
        ),
        ("nav_behaviours", "robot", 60, "[nav] t=  1.0 s"),
        ("control_loop", "bench", 1000, ""),
    ] {
        programs_match_ferroc_run(name, &[part], cycles, must_print);
    }
}

/// A client in one part calling a service in another (`ferroc_std.Ask` and
/// `ferroc_std.ScaleService`): the call and its answer cross over TCP.
#[test]
fn a_service_call_between_two_programs() {
    let source = "tests/fixtures/calls_between_parts.xml";
    let dir = tempdir("bundle_links_calls_source");
    bundle_ok(
        &copy_model_from(source, "remote_calls", &dir),
        &dir.join("b"),
    );
    let asker = std::fs::read_to_string(dir.join("b/parts/asker/src/main.rs")).unwrap();
    for line in [
        "builder.call_out(&CALL_0, (ASK, \"ask\"))?;",
        "registry.register_call::<f64, f64>();",
        "    server_part: \"server\",",
    ] {
        assert!(asker.contains(line), "{line} missing in\n{asker}");
    }
    programs_match(
        source,
        "remote_calls",
        &["asker", "server"],
        40,
        "twice the tick: in/0 = 8",
    );
}

/// A port in one part driving a parameter in another (`tests/fixtures/param_between_parts.xml`).
#[test]
fn a_parameter_set_from_another_program() {
    let source = "tests/fixtures/param_between_parts.xml";
    let dir = tempdir("bundle_links_param_source");
    bundle_ok(
        &copy_model_from(source, "remote_param", &dir),
        &dir.join("b"),
    );
    let robot = std::fs::read_to_string(dir.join("b/parts/robot/src/main.rs")).unwrap();
    let tuning = std::fs::read_to_string(dir.join("b/parts/tuning/src/main.rs")).unwrap();
    assert!(
        robot.contains("builder.link_in_param(&LINK_0, (SCALED, \"factor\"))?;"),
        "{robot}"
    );
    assert!(
        tuning.contains(
            "builder.link_out(&LINK_0, (GAIN, \"value\"), Conversion::linear(1.0, 0.0))?;"
        ),
        "{tuning}"
    );
    programs_match(
        source,
        "remote_param",
        &["tuning", "robot"],
        20,
        "scaled speed: in/0 = 10",
    );
}

/// `<part shared-memory…>` reaches the part's program: its `SHARED_MEMORY` constant,
/// given to `Zenoh::with_model`; a part without the attributes keeps every default.
#[test]
fn a_parts_shared_memory_settings_reach_its_program() {
    let dir = tempdir("bundle_links_shared_memory");
    let model = copy_model("rescue_robot", &dir);
    let text = std::fs::read_to_string(&model).unwrap().replace(
        "<part name=\"robot\" host=\"robot-pc\">",
        "<part name=\"robot\" host=\"robot-pc\" shared-memory-pool=\"128 MiB\" \
         shared-memory-threshold=\"16 KiB\">",
    );
    std::fs::write(&model, text).unwrap();
    bundle_ok(&model, &dir.join("b"));
    let read = |part: &str| {
        std::fs::read_to_string(dir.join(format!("b/parts/{part}/src/main.rs"))).unwrap()
    };
    let (robot, station) = (read("robot"), read("station"));
    for text in [&robot, &station] {
        let call = text.split("Zenoh::with_model(").nth(1).unwrap_or_default();
        assert!(
            call.split(')').take(2).any(|a| a.contains("SHARED_MEMORY")),
            "the network is made with the model's settings:\n{text}"
        );
    }
    for line in [
        "enabled: None,",
        "threshold: Some(16384),",
        "pool: Some(134217728),",
    ] {
        assert!(robot.contains(line), "{line} missing in\n{robot}");
    }
    for line in ["enabled: None,", "threshold: None,", "pool: None,"] {
        assert!(station.contains(line), "{line} missing in\n{station}");
    }
}
