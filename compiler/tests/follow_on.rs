//! One root cause, one finding (rustc's rule): a finding that is a consequence of one
//! already reported is not reported again. Each case edits a real model once and
//! compares its findings with those of the model as it is.

use ferroc_compiler::load::{BuiltinLibrary, Options};
use ferroc_compiler::{check_model, Policy};
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

fn options() -> Options {
    Options {
        builtins: vec![BuiltinLibrary {
            name: "ferroc_std".into(),
            text: include_str!("../../components/ferroc_std.lib.xml").into(),
        }],
        ..Options::default()
    }
}

/// Findings as `CODE message`, of `text` checked as a file in `models/` (so that its
/// relative manifests and includes resolve).
fn findings(text: &str) -> Vec<String> {
    // Tests run in parallel: each file gets a name of its own.
    static NEXT: AtomicUsize = AtomicUsize::new(0);
    let n = NEXT.fetch_add(1, Ordering::Relaxed);
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../models");
    let path = dir.join(format!(".follow-on-{}-{n}.xml", std::process::id()));
    std::fs::write(&path, text).unwrap();
    let result = check_model(&path, &options(), &Policy::default());
    let _ = std::fs::remove_file(&path);
    result
        .unwrap()
        .diagnostics
        .iter()
        .map(|d| format!("{} {}", d.code(), d.message))
        .collect()
}

/// The codes of the findings the edit adds to those of the model as it is.
fn added(model: &str, from: &str, to: &str) -> Vec<String> {
    assert_eq!(model.matches(from).count(), 1, "`{from}` must occur once");
    let before = findings(model);
    let after = findings(&model.replacen(from, to, 1));
    let new: Vec<String> = after.into_iter().filter(|f| !before.contains(f)).collect();
    let codes = new.iter().map(|f| f[..4].to_string()).collect();
    eprintln!("{from} -> {to}:\n{}", new.join("\n"));
    codes
}

const CRASH: &str = include_str!("../../models/crash_course.xml");
const FLEET: &str = include_str!("../../models/warehouse_fleet.xml");

#[test]
fn a_misspelt_module_type_is_one_finding() {
    // Was: M111, two T109 (inputs it fed) and ten M110 (paths through it).
    assert_eq!(
        added(
            CRASH,
            "type=\"crash_course.MainSimulation\"",
            "type=\"crash_course.MainSimulatoin\""
        ),
        ["M111"]
    );
}

#[test]
fn a_misspelt_library_is_one_finding() {
    assert_eq!(
        added(
            CRASH,
            "type=\"crash_course.MainSimulation\"",
            "type=\"crash_cours.MainSimulation\""
        ),
        ["L101"]
    );
}

#[test]
fn a_misspelt_group_type_is_one_finding() {
    // Was: M111 and five M110 ("has no element or port") for paths into the group.
    assert_eq!(
        added(
            FLEET,
            "<group name=\"statistics\" type=\"local.FleetStatistics\"/>",
            "<group name=\"statistics\" type=\"local.FleetStatistic\"/>"
        ),
        ["M111"]
    );
}

#[test]
fn a_misspelt_attribute_is_read_as_the_one_meant() {
    // Was: M103 and M108 ("has neither `period` nor `trigger`").
    assert_eq!(
        added(
            CRASH,
            "period=\"40ms\" priority=\"50\"",
            "perod=\"40ms\" priority=\"50\""
        ),
        ["M103"]
    );
    // Was: M103, M104 (no `name`), two T109 and ten M110.
    assert_eq!(
        added(
            CRASH,
            "<module name=\"main_simulation\"",
            "<module nme=\"main_simulation\""
        ),
        ["M103"]
    );
}

#[test]
fn an_unresolved_path_does_not_also_leave_its_other_end_unconnected() {
    // Was: M110 and T109 for the required input the connection feeds.
    assert_eq!(
        added(
            CRASH,
            "from=\"main_simulation/ir_distance_front\" to=\"add_noise_front/input\"",
            "from=\"main_simulaton/ir_distance_front\" to=\"add_noise_front/input\""
        ),
        ["M110"]
    );
}

/// What is not a consequence is still reported.
#[test]
fn independent_findings_stay() {
    // The attribute meant is there already: nothing is read in its place.
    assert_eq!(
        added(
            CRASH,
            "<module name=\"main_simulation\"",
            "<module name=\"main_simulation\" nme=\"other\""
        ),
        ["M103"]
    );
    // The misspelt attribute's value is wrong too: a second, real problem.
    assert_eq!(
        added(
            CRASH,
            "period=\"40ms\" priority=\"50\"",
            "perod=\"0ms\" priority=\"50\""
        ),
        ["M103", "M108"]
    );
    // A misspelt path to a module that exists is reported, not taken for a follow-on.
    assert_eq!(
        added(
            CRASH,
            "<connect from=\"velocity\" to=\"main_simulation/velocity\"/>",
            "<connect from=\"velocity\" to=\"main_simulaton/velocity\"/>"
        ),
        ["M110"]
    );
}
