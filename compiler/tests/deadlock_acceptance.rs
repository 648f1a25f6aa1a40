//! Acceptance of the deadlock analysis (issue 5) on models written apart from the 35
//! examples of `reference/deadlocks.md` (`tests/deadlock_examples/`): a call cycle across
//! three parts, a service calling back through a group port, a lock inversion hidden in
//! group types, queue rings with and without an initial item, a ring that fills up — and
//! each made safe (a timeout, an asynchronous call, an initial item, a drop policy, one
//! thread). Every D finding is asserted with its code, severity and line:col; the safe
//! models must have no D error or warning. Types: `tests/deadlock_acceptance/acc.lib.xml`.

use ferroc_compiler::diagnostic::Severity;
use ferroc_compiler::load::{BuiltinLibrary, Options};
use ferroc_compiler::{check_model, Policy};
use std::path::Path;

fn options() -> Options {
    Options {
        builtins: vec![BuiltinLibrary {
            name: "ferroc_std".into(),
            text: include_str!("../../components/ferroc_std.lib.xml").into(),
        }],
        ..Options::default()
    }
}

/// A finding as compared: code, severity, line, column, and a word its message names.
type Expect = (&'static str, Severity, usize, usize, &'static str);

/// model, its D findings (all of them, in order).
const CASES: &[(&str, &[Expect])] = &[
    (
        "call_cycle_three_parts.xml",
        &[(
            "D101",
            Severity::Error,
            22,
            18,
            "`base/dispatch` → `arm/ctrl` → `hand/grip` → `base/dispatch`",
        )],
    ),
    (
        "call_cycle_three_parts_timeout.xml",
        &[(
            "D113",
            Severity::Warning,
            23,
            18,
            "always times out after 30 ms",
        )],
    ),
    (
        "callback_through_group_port.xml",
        &[(
            "D101",
            Severity::Error,
            11,
            20,
            "`robot/servo` → `robot/planning` → `robot/servo`",
        )],
    ),
    ("callback_through_group_port_async.xml", &[]),
    (
        "lock_inversion_in_group_types.xml",
        &[(
            "D103",
            Severity::Error,
            18,
            36,
            "take locks in opposite orders",
        )],
    ),
    (
        "lock_inversion_in_group_types_timeout.xml",
        &[(
            "D114",
            Severity::Note,
            19,
            36,
            "only a timeout of 5 ms breaks it",
        )],
    ),
    (
        "lock_inversion_one_thread.xml",
        &[("D117", Severity::Note, 18, 36, "`robot/estimation`")],
    ),
    (
        "queue_ring_empty.xml",
        &[("D106", Severity::Error, 13, 42, "holds no item (0 tokens)")],
    ),
    ("queue_ring_with_token.xml", &[]),
    (
        "queue_ring_full.xml",
        &[("D107", Severity::Error, 10, 48, "can fill up")],
    ),
    ("queue_ring_full_drop.xml", &[]),
];

#[test]
fn every_finding_at_its_place_and_safe_models_silent() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/deadlock_acceptance");
    let mut failures = Vec::new();
    for (model, expected) in CASES {
        let result = check_model(&dir.join(model), &options(), &Policy::default())
            .unwrap_or_else(|e| panic!("{model}: {e:?}"));
        let found: Vec<(&str, Severity, usize, usize, String)> = result
            .diagnostics
            .iter()
            .filter(|d| d.code().starts_with('D'))
            .map(|d| {
                let (_, l, c) = result.sources.location(d.primary.span);
                (d.code(), d.severity, l, c, d.message.clone())
            })
            .collect();
        let same = found.len() == expected.len()
            && found.iter().zip(expected.iter()).all(|(f, e)| {
                f.0 == e.0 && f.1 == e.1 && f.2 == e.2 && f.3 == e.3 && f.4.contains(e.4)
            });
        if !same {
            failures.push(format!("{model}: expected {expected:?}\n  found {found:?}"));
        }
        // The models are otherwise valid: no error outside area D.
        for d in result.diagnostics.iter() {
            if !d.code().starts_with('D') && d.severity == Severity::Error {
                failures.push(format!("{model}: unexpected {}: {}", d.code(), d.message));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn every_model_in_the_folder_is_asserted() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/deadlock_acceptance");
    let mut models: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".xml") && !n.ends_with(".lib.xml"))
        .collect();
    models.sort();
    let mut listed: Vec<String> = CASES.iter().map(|(m, _)| m.to_string()).collect();
    listed.sort();
    assert_eq!(models, listed);
}
