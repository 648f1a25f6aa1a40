//! Acceptance of the iB2C rules (B) on a realistic behaviour network, written apart from
//! the per-check fixtures: `tests/behaviour_acceptance/clean.xml` is a delivery robot
//! (goal following, wall following and obstacle avoidance fused in an iB2C group, mutual
//! inhibition, docking on low battery) with no B finding; every other model there is the
//! same network with one mistake, which must give exactly one B finding at its line.
//! The behaviour types are `components/nav_behaviours.lib.xml`.

use ferroc_compiler::diagnostic::{Diagnostic, Severity};
use ferroc_compiler::load::{BuiltinLibrary, Options};
use ferroc_compiler::source::SourceMap;
use ferroc_compiler::{check_model, Policy};
use std::path::{Path, PathBuf};

fn options() -> Options {
    Options {
        builtins: vec![BuiltinLibrary {
            name: "ferroc_std".into(),
            text: include_str!("../../components/ferroc_std.lib.xml").into(),
        }],
        ..Options::default()
    }
}

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/behaviour_acceptance")
}

/// One B finding as the tests compare it.
#[derive(Debug, PartialEq)]
struct Finding {
    code: &'static str,
    severity: Severity,
    line: usize,
}

/// The findings of a model: the B ones (with their diagnostics), and every other code.
fn check(name: &str) -> (Vec<(Finding, Diagnostic)>, Vec<&'static str>, SourceMap) {
    let path = dir().join(name);
    let result = check_model(&path, &options(), &Policy::default()).expect("model readable");
    let mut b = Vec::new();
    let mut others = Vec::new();
    for d in result.diagnostics {
        if d.code().starts_with('B') {
            let (_, line, _) = result.sources.location(d.primary.span);
            let f = Finding {
                code: d.code(),
                severity: d.severity,
                line,
            };
            b.push((f, d));
        } else {
            others.push(d.code());
        }
    }
    (b, others, result.sources)
}

/// model, the one B finding expected (code, severity, line), words its message names.
type Case = (
    &'static str,
    (&'static str, Severity, usize),
    &'static [&'static str],
);

const CASES: &[Case] = &[
    (
        "number_stimulation.xml",
        ("B102", Severity::Error, 107),
        &["robot/control/dock/stimulation", "robot/sense/battery/charge", "`f64`"],
    ),
    (
        "wrong_activity.xml",
        ("B109", Severity::Error, 86),
        &["channel 2", "navigation/go_to_goal", "navigation/avoid", "`activity`"],
    ),
    (
        "self_inhibition.xml",
        ("B106", Severity::Error, 114),
        &["robot/control/navigation/fusion", "group ports"],
    ),
    (
        "stimulation_loop.xml",
        ("B107", Severity::Warning, 106),
        &["`robot/control/navigation/go_to_goal` → `robot/control/dock` → `robot/control/navigation/go_to_goal`"],
    ),
    (
        "two_characteristic.xml",
        ("B110", Severity::Error, 55),
        &["robot/control/navigation", "`avoid` and `fusion`"],
    ),
    (
        "inhibition_two_sources.xml",
        ("B105", Severity::Error, 69),
        &["go_to_goal/inhibition/0", "2 sources"],
    ),
];

#[test]
fn the_clean_network_with_mutual_inhibition_has_no_finding() {
    let (b, others, _) = check("clean.xml");
    assert!(b.is_empty(), "B findings on the clean network: {b:#?}");
    assert!(
        others.is_empty(),
        "other findings on the clean network: {others:?}"
    );
}

#[test]
fn each_mistake_gives_its_b_finding_at_its_line() {
    let mut failures = Vec::new();
    for (model, (code, severity, line), words) in CASES {
        let (b, others, _) = check(model);
        let found: Vec<&Finding> = b.iter().map(|(f, _)| f).collect();
        let expected = Finding {
            code,
            severity: *severity,
            line: *line,
        };
        if found != [&expected] {
            failures.push(format!(
                "{model}: expected exactly {expected:?}, found {found:?}"
            ));
            continue;
        }
        let d = &b[0].1;
        for w in *words {
            if !d.message.contains(w) {
                failures.push(format!("{model}: message lacks `{w}`: {}", d.message));
            }
        }
        if d.help.is_none() {
            failures.push(format!("{model}: {code} has no help"));
        }
        // Nothing else may be an error: each model has exactly one mistake.
        if let Some(other) = others.iter().find(|c| !c.starts_with('S')) {
            failures.push(format!("{model}: unexpected finding {other}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn every_inhibition_source_gets_a_secondary_label() {
    let (b, _, sources) = check("inhibition_two_sources.xml");
    let d = &b[0].1;
    let lines: Vec<usize> = d
        .secondary
        .iter()
        .map(|l| sources.location(l.span).1)
        .collect();
    // follow_wall/activity (line 67) and avoid/activity/emergency (line 69) into go_to_goal.
    assert_eq!(lines, [67, 69], "{:#?}", d.secondary);
    assert!(d
        .secondary
        .iter()
        .any(|l| l.message.contains("follow_wall/activity")));
    assert!(d
        .secondary
        .iter()
        .any(|l| l.message.contains("avoid/activity/emergency")));
}

#[test]
fn every_model_in_the_folder_is_covered() {
    let mut names: Vec<String> = std::fs::read_dir(dir())
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".xml"))
        .collect();
    names.sort();
    let mut covered: Vec<String> = CASES.iter().map(|c| c.0.to_string()).collect();
    covered.push("clean.xml".into());
    covered.sort();
    assert_eq!(names, covered);
}
