use super::*;
use std::sync::atomic::{AtomicU64, Ordering};

fn resources(names: &[(&str, Option<u32>, bool)]) -> (Arc<LockOrder>, Vec<Arc<Resource>>) {
    let order = Arc::new(LockOrder::new());
    let rs = names
        .iter()
        .map(|(n, level, rec)| Resource::new(n, *level, *rec, &order))
        .collect();
    (order, rs)
}

#[test]
fn an_inversion_is_reported_with_both_sites_before_anything_hangs() {
    let (order, r) = resources(&[("map", None, false), ("pose", None, false)]);
    let (map, pose) = (&r[0], &r[1]);
    {
        let _m = map.lock("robot/planner");
        let _p = pose.lock("robot/planner"); // line A: pose while holding map
    }
    assert!(order.reports().is_empty());
    {
        let _p = pose.lock("robot/localiser");
        let _m = map.lock("robot/localiser"); // line B: map while holding pose
    }
    let reports = order.reports();
    assert_eq!(reports.len(), 1, "{reports:?}");
    let r = &reports[0];
    assert!(
        r.starts_with("lock order inversion: `map` is taken while holding `pose`"),
        "{r}"
    );
    // Both acquisition sites: this file, the module paths, and the help.
    assert_eq!(
        r.matches("runtime/module/src/resource/tests.rs:").count(),
        4,
        "{r}"
    );
    assert!(
        r.contains("in `robot/localiser`") && r.contains("in `robot/planner`"),
        "{r}"
    );
    assert!(
        r.contains("help: take `map` and `pose` in one order everywhere"),
        "{r}"
    );
    // Reported once per pair, however often it happens again.
    for _ in 0..3 {
        let _p = pose.lock("robot/localiser");
        let _m = map.lock("robot/localiser");
    }
    assert_eq!(order.reports().len(), 1);
}

#[test]
fn a_declared_order_is_enforced_on_the_first_contrary_acquisition() {
    let (order, r) = resources(&[("bus", None, false), ("log", None, false)]);
    order.declare(
        r[0].id(),
        r[1].id(),
        "<locks order=\"bus log\"> of driver.Io".into(),
    );
    let _l = r[1].lock("robot/io");
    let _b = r[0].lock("robot/io");
    let reports = order.reports();
    assert_eq!(reports.len(), 1, "{reports:?}");
    assert!(
        reports[0]
            .contains("declared: `bus` before `log` (<locks order=\"bus log\"> of driver.Io)"),
        "{}",
        reports[0]
    );
}

#[test]
fn consistent_and_unnested_orders_stay_silent() {
    let (order, r) = resources(&[("a", None, false), ("b", None, false), ("c", None, false)]);
    let (a, b, c) = (&r[0], &r[1], &r[2]);
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| {
                for _ in 0..100 {
                    let _a = a.lock("m");
                    let _b = b.lock("m");
                    let _c = c.lock("m");
                }
                let _a = a.lock("m");
                let _c = c.lock("m");
            });
        }
    });
    // b alone, then a alone: never nested, so no order between them.
    drop(b.lock("m"));
    drop(a.lock("m"));
    assert!(order.reports().is_empty(), "{:?}", order.reports());
}

#[test]
fn a_transitive_inversion_is_found_through_the_chain() {
    let (order, r) = resources(&[("a", None, false), ("b", None, false), ("c", None, false)]);
    {
        let _a = r[0].lock("m1");
        let _b = r[1].lock("m1");
    }
    {
        let _b = r[1].lock("m2");
        let _c = r[2].lock("m2");
    }
    {
        let _c = r[2].lock("m3");
        let _a = r[0].lock("m3");
    }
    let reports = order.reports();
    assert_eq!(reports.len(), 1, "{reports:?}");
    // The earlier path a → b → c is shown hop by hop.
    assert_eq!(
        reports[0].matches("  before: ").count(),
        2,
        "{}",
        reports[0]
    );
}

#[test]
fn levels_must_rise() {
    let (order, r) = resources(&[("low", Some(1), false), ("high", Some(2), false)]);
    drop((r[0].lock("m"), r[1].lock("m")));
    assert!(order.reports().is_empty());
    let _h = r[1].lock("m");
    let _l = r[0].lock("m");
    let reports = order.reports();
    assert!(
        reports.iter().any(|t| t.starts_with(
            "lock level violation: `low` (level 1) is taken while holding `high` (level 2)"
        )),
        "{reports:?}"
    );
}

#[test]
fn retaking_a_plain_resource_panics_with_a_report_instead_of_hanging() {
    let (order, r) = resources(&[("map", None, false)]);
    let map = Arc::clone(&r[0]);
    let outcome = std::thread::spawn(move || {
        let _first = map.lock("m");
        let _second = map.lock("m");
    })
    .join();
    assert!(outcome.is_err());
    assert!(order.reports()[0].starts_with("recursive lock: `map` is taken again"));
    // The panic released it: another thread can take it.
    drop(r[0].lock("m"));
}

#[test]
fn a_recursive_resource_may_be_retaken_by_its_holder() {
    let (order, r) = resources(&[("tree", None, true)]);
    let _a = r[0].lock("m");
    let _b = r[0].lock("m");
    assert!(order.reports().is_empty());
}

#[test]
fn a_resource_excludes_other_threads() {
    let (_, r) = resources(&[("counter", None, false)]);
    let value = AtomicU64::new(0);
    std::thread::scope(|s| {
        for _ in 0..4 {
            s.spawn(|| {
                for _ in 0..500 {
                    let _g = r[0].lock("m");
                    // A read-modify-write split in two: exact only under exclusion.
                    let v = value.load(Ordering::Relaxed);
                    std::thread::yield_now();
                    value.store(v + 1, Ordering::Relaxed);
                }
            });
        }
    });
    assert_eq!(value.load(Ordering::Relaxed), 2000);
}
