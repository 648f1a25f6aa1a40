use super::layout::{GroupKind, Layout};
use super::*;
use ferroc_compiler::deadlock::{self, WaitKind};
use ferroc_compiler::diagnostic::Severity;
use ferroc_compiler::load::{BuiltinLibrary, Options};
use ferroc_compiler::{check_model, CheckResult, Policy};

#[test]
fn layout_follows_b1() {
    let l = Layout::new(100_000);
    assert_eq!((l.groups, l.threads, l.parts), (10_000, 1_000, 20));
    assert_eq!(l.blocks(), 100);
    let l = Layout::new(1_000);
    assert_eq!((l.groups, l.threads, l.parts), (100, 10, 1));
    assert_eq!(Layout::new(7).groups, 1);
    // A short last block is served by its last container, which is then periodic.
    let l = Layout::new(1_500);
    assert_eq!((l.threads, l.hub_of(10), l.hub_of(14)), (15, 14, 14));
    assert!(!l.data_triggered(14) && l.priority(14).is_none());
    assert_eq!(l.priority(3), l.priority(8));
}

/// Counts of each kind of group: (kind, how many).
fn kinds(l: &Layout) -> impl Fn(GroupKind) -> usize + '_ {
    move |k| (0..l.groups).filter(|&g| l.kind(g) == k).count()
}

#[test]
fn model_has_n_modules_and_two_data_connections_each() {
    let text = generate(1_000);
    let l = Layout::new(1_000);
    let count = kinds(&l);
    // The group type's body is written once and counts once per instance.
    let instances = text.matches("type=\"local.Filter\"").count();
    assert_eq!(instances, count(GroupKind::Instance));
    let per_instance =
        |written: usize, per_group: usize| written - per_group + instances * per_group;
    assert_eq!(
        per_instance(text.matches("<module ").count(), GROUP_SIZE),
        1_000
    );
    // Besides data: per client group three calls to the hub and one inline call.
    let clients = count(GroupKind::Client);
    assert!(clients > 0);
    assert_eq!(
        per_instance(text.matches("<connect ").count(), 18),
        2 * 1_000 + 4 * clients
    );
    assert_eq!(text.matches(" to=\"p0/t9/g0/smooth/get\"").count(), clients);
}

fn options() -> Options {
    Options {
        builtins: vec![BuiltinLibrary {
            name: "ferroc_std".into(),
            text: include_str!("../../../components/ferroc_std.lib.xml").into(),
        }],
        ..Default::default()
    }
}

/// Checks `text` as a model next to the `b1` manifest, in a folder of its own.
fn check(name: &str, text: &str) -> CheckResult {
    let dir = std::env::temp_dir().join(format!("ferroc-bench-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("b1.xml");
    std::fs::write(&path, text).unwrap();
    std::fs::write(dir.join(MANIFEST_FILE), MANIFEST).unwrap();
    let result = check_model(&path, &options(), &Policy::default()).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    result
}

fn findings(result: &CheckResult) -> Vec<String> {
    result
        .diagnostics
        .iter()
        .map(|d| format!("{} {:?}: {}", d.code(), d.severity, d.message))
        .collect()
}

/// The generated model checks without any finding, and the deadlock analysis saw
/// every wait the generator put in: the calls, locks and blocking reads are really
/// part of what was checked.
#[test]
fn generated_model_checks_clean_with_waits() {
    const N: usize = 2_000;
    let result = check("clean", &generate(N));
    assert!(
        result.diagnostics.is_empty(),
        "findings:\n{}",
        findings(&result).join("\n")
    );
    let app = result.app.as_ref().expect("the model resolves");
    let l = Layout::new(N);
    let count = kinds(&l);
    let (clients, locking, inboxes) = (
        count(GroupKind::Client),
        count(GroupKind::Locking),
        count(GroupKind::Inbox),
    );
    let hubs = l.blocks();
    assert_eq!((clients, locking, inboxes, hubs), (46, 36, 16, 2));

    let m = deadlock::model(app, &result.libraries);
    let calls = |timed: bool| {
        m.waits
            .iter()
            .filter(|w| matches!(&w.kind, WaitKind::Call { targets, .. } if targets.len() == 1))
            .filter(|w| w.timeout.is_some() == timed)
            .count()
    };
    // Planner's `map` (no timeout) and Tracker's `pose` (200 us); the async `notify`
    // and the inline calibration call are no waits.
    assert_eq!(calls(false), clients);
    assert_eq!(calls(true), clients);
    let lock_waits = m
        .waits
        .iter()
        .filter(|w| matches!(w.kind, WaitKind::Lock { .. }))
        .count();
    // Estimator: map, pose; each hub's map server twice: in the `get` body and in its
    // default update activity (which takes every slot its steps name).
    assert_eq!(lock_waits, 2 * locking + 4 * hubs);
    // Pose is taken holding map (and the own container).
    assert!(m
        .waits
        .iter()
        .filter(|w| matches!(w.kind, WaitKind::Lock { lock } if m.locks[lock as usize].name.starts_with("pose")))
        .all(|w| w.held.len() == 2));
    let reads: Vec<_> = m
        .waits
        .iter()
        .filter_map(|w| match w.kind {
            WaitKind::Read { queue } => Some((w.timeout, &m.queues[queue as usize])),
            _ => None,
        })
        .collect();
    assert_eq!(reads.len(), inboxes);
    assert!(reads
        .iter()
        .all(|(t, q)| *t == Some(0.001) && q.is_queue && q.capacity == Some(8)));
    assert_eq!(m.locks.len(), 2 * hubs);
    assert!(m
        .locks
        .iter()
        .all(|k| k.span.is_some() && k.level.is_some()));
    let a = deadlock::analyse(app, &result.libraries, &m);
    assert!(a.cycles.is_empty() && a.hangs.is_empty() && a.latent.is_empty());
}

/// Small sizes have other shapes: one container (its own hub, periodic), two, one
/// block whose ring closes from the hub into the block's first container, a short
/// last block. Each checks without any finding.
#[test]
fn small_models_check_clean_too() {
    for n in [50, 200, 1_000, 1_500] {
        let result = check(&format!("small{n}"), &generate(n));
        assert!(
            result.diagnostics.is_empty(),
            "N={n}:\n{}",
            findings(&result).join("\n")
        );
        assert!(result.app.is_some());
    }
}

/// One Estimator taking the two locks the other way round is a lock-order inversion
/// (D103) against the modules of its block that take map before pose, so the checked model does contain lock waits
/// whose order matters.
#[test]
fn one_flipped_lock_order_is_a_deadlock() {
    let text = generate(2_000);
    let (map, pose) = (
        "<bind lock=\"map\" resource=\"map0\"/>",
        "<bind lock=\"pose\" resource=\"pose0\"/>",
    );
    let first = text.find(map).expect("a bind of map0");
    assert!(text[first..].starts_with(&format!("{map}\n")) && text[first..].contains(pose));
    let flipped = text
        .replacen(map, "<bind lock=\"map\" resource=\"pose0\"/>", 1)
        .replacen(pose, "<bind lock=\"pose\" resource=\"map0\"/>", 1);
    let result = check("flipped", &flipped);
    let errors: Vec<_> = result
        .diagnostics
        .iter()
        .filter(|d| d.severity == Severity::Error)
        .collect();
    assert_eq!(
        errors.iter().map(|d| d.code()).collect::<Vec<_>>(),
        ["D103"],
        "findings:\n{}",
        findings(&result).join("\n")
    );
    // The flipped module sits in `p0/t0`; every other taker of map0 and pose0 is a
    // partner of the inversion (the witness names one).
    let d = errors[0];
    assert!(d.message.contains("opposite orders") && d.message.contains("`p0/t0`"));
    assert_eq!(d.witness.len(), 2, "one flow per blocked thread container");
}

/// The model with findings has exactly one T107 per repeated connection, each pointing
/// back at the first connection, and nothing else.
#[test]
fn model_with_findings_has_one_duplicate_warning_per_repeat() {
    const N: usize = 1_000;
    let result = check("findings", &generate_with_findings(N));
    assert_eq!(findings_in(N), 34);
    assert_eq!(
        result.diagnostics.len(),
        findings_in(N),
        "{:#?}",
        findings(&result)
    );
    for d in &result.diagnostics {
        assert_eq!((d.code(), d.severity), ("T107", Severity::Warning));
        assert_eq!(d.secondary.len(), 1);
        assert!(d.secondary[0].span.start < d.primary.span.start);
    }
}
