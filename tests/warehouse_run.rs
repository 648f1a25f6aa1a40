//! `ferroc run` on one simulated warehouse AGV (`tests/fixtures/warehouse_one_agv.xml`):
//! the warehouse library's modules take a WMS order through the fleet manager, drive,
//! lift and report it end to end, and the output depends only on the number of cycles.

mod common;

use common::{ferroc, tempdir};

const MODEL: &str = "tests/fixtures/warehouse_one_agv.xml";

/// The dashboard's status lines (one every other cycle in this model).
fn status_lines(stdout: &str) -> Vec<&str> {
    stdout
        .lines()
        .filter(|l| l.starts_with("[one agv] t="))
        .collect()
}

#[test]
fn an_agv_fetches_a_shelf_and_delivers_it() {
    let (code, out, err) = ferroc(&["run", MODEL, "--cycles", "6000", "-q"]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("agv/all: 6000 cycles"), "{err}");
    let events: Vec<&str> = out.lines().filter(|l| l.starts_with("[agv 1]")).collect();
    assert_eq!(
        events,
        [
            "[agv 1] task 1: shelf at (11.0, 1.5) to (0.5, 0.0)",
            "[agv 1] task 1 delivered (1 done)",
            "[agv 1] task 2: shelf at (11.0, 1.5) to (0.5, 2.0)",
        ],
        "{out}"
    );
    let lines = status_lines(&out);
    assert_eq!(lines.len(), 3000, "a line every other of 6000 cycles");
    // Parked at home (1 m, 0 m) before the first order, idle.
    assert!(
        lines[400].ends_with("robot 1: idle task 0 at (+1.0, +0.0) battery 95% done 0"),
        "{}",
        lines[400]
    );
    // On the way: busy with task 1 somewhere in the shelf area.
    assert!(
        lines
            .iter()
            .any(|l| l.contains("busy task 1 at (+11.0, +1.5)")),
        "never at the pickup (11, 1.5)"
    );
    // At the end: one delivered, on the way to the second shelf (it waits at 11, 1.5).
    let last = lines.last().copied().unwrap_or_default();
    assert!(
        last.contains("busy task 2") && last.ends_with("done 1"),
        "{last}"
    );
}

#[test]
fn the_output_depends_only_on_the_number_of_cycles() {
    let (code, first, err) = ferroc(&["run", MODEL, "--cycles", "2500", "-q"]);
    assert_eq!(code, 0, "{err}");
    let (_, second, _) = ferroc(&["run", MODEL, "--cycles", "2500", "-q"]);
    assert_eq!(first, second);
    assert_eq!(status_lines(&first).len(), 1250);
}

#[test]
fn a_fleet_manager_with_unpaired_robot_ports_is_refused_by_name() {
    let model = std::fs::read_to_string(MODEL).unwrap().replace(
        r#"<port name="task" dir="out" type="warehouse.Task" count="1"/>"#,
        r#"<port name="task" dir="out" type="warehouse.Task" count="2"/>"#,
    );
    let root = env!("CARGO_MANIFEST_DIR");
    let model = model.replace("../../components/", &format!("{root}/components/"));
    let path = tempdir("warehouse_unpaired").join("model.xml");
    std::fs::write(&path, model).unwrap();
    let (code, out, err) = ferroc(&["run", path.to_str().unwrap(), "--cycles", "5", "-q"]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(
        err.contains("`agv/all/fleet` could not be created: 1 status inputs but 2 task outputs"),
        "{err}"
    );
}
