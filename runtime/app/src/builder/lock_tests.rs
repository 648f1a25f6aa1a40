//! Application resources through the Builder: slots bound by the model, orders
//! declared by module types, inversions reported while the application runs.

use super::*;
use ferroc_module::resource::LockSlot;
use ferroc_module::ModuleType;

/// Takes `outer`, then `inner`, every cycle.
struct Nested {
    outer: LockSlot,
    inner: LockSlot,
}
impl Module for Nested {
    fn update(&mut self) {
        let _outer = self.outer.lock();
        let _inner = self.inner.lock();
    }
}
impl ModuleType for Nested {
    const NAME: &'static str = "test.Nested";
    fn create(m: &mut Setup<'_>) -> Self {
        Nested {
            outer: m.lock("outer"),
            inner: m.lock("inner"),
        }
    }
}

fn builder_with<'r>(registry: &'r Registry, modules: &[(&str, &str, &str)]) -> Builder<'r> {
    let mut b = Builder::new(registry);
    b.add_resource("a", None, false).unwrap();
    b.add_resource("b", None, false).unwrap();
    for (path, outer, inner) in modules {
        b.add_module(ModuleSpec {
            path,
            type_name: "test.Nested",
            params: &[],
            queues: &[],
            ports: &[],
            violations: Default::default(),
        })
        .unwrap();
        b.bind_lock(path, "outer", outer).unwrap();
        b.bind_lock(path, "inner", inner).unwrap();
    }
    b.add_thread(ThreadSpec {
        path: "main".into(),
        schedule: Schedule::Periodic(Duration::from_micros(100)),
        options: ThreadOptions::default(),
        steps: modules
            .iter()
            .map(|(p, _, _)| (p.to_string(), StepKind::Update))
            .collect(),
    })
    .unwrap();
    b
}

fn registry() -> Registry {
    let mut r = Registry::new();
    r.register::<Nested>();
    r
}

#[test]
fn opposite_orders_in_two_modules_are_reported_once_with_module_paths() {
    let registry = registry();
    let b = builder_with(&registry, &[("m1", "a", "b"), ("m2", "b", "a")]);
    let mut app = b.start(Some(5)).unwrap();
    app.join();
    let reports = app.lock_reports();
    assert_eq!(reports.len(), 1, "{reports:?}");
    assert!(
        reports[0].contains("`a` is taken while holding `b`"),
        "{}",
        reports[0]
    );
    assert!(
        reports[0].contains("in `m2`") && reports[0].contains("in `m1`"),
        "{}",
        reports[0]
    );
    assert!(app.panics().is_empty());
}

#[test]
fn a_declared_order_catches_the_only_module_that_breaks_it() {
    let registry = registry();
    let mut b = builder_with(&registry, &[("m2", "b", "a")]);
    b.declare_lock_order("a", "b", "<locks order=\"a b\"> of `dl.LockAB`")
        .unwrap();
    let mut app = b.start(Some(1)).unwrap();
    app.join();
    let reports = app.lock_reports();
    assert_eq!(reports.len(), 1, "{reports:?}");
    assert!(
        reports[0].contains("declared: `a` before `b`"),
        "{}",
        reports[0]
    );
}

#[test]
fn the_same_order_everywhere_is_silent_and_unbound_slots_use_their_own_name() {
    let registry = registry();
    let b = builder_with(&registry, &[("m1", "a", "b"), ("m2", "a", "b")]);
    let mut app = b.start(Some(5)).unwrap();
    app.join();
    assert!(app.lock_reports().is_empty(), "{:?}", app.lock_reports());

    let mut b = Builder::new(&registry);
    b.add_module(ModuleSpec {
        path: "solo",
        type_name: "test.Nested",
        params: &[],
        queues: &[],
        ports: &[],
        violations: Default::default(),
    })
    .unwrap();
    b.add_thread(thread_of("solo")).unwrap();
    let mut app = b.start(Some(2)).unwrap();
    app.join();
    assert!(app.panics().is_empty() && app.lock_reports().is_empty());
}

fn thread_of(path: &str) -> ThreadSpec {
    ThreadSpec {
        path: "t".into(),
        schedule: Schedule::Periodic(Duration::from_micros(100)),
        options: ThreadOptions::default(),
        steps: vec![(path.into(), StepKind::Update)],
    }
}

#[test]
fn resource_mistakes_are_error_values() {
    let registry = registry();
    let mut b = builder_with(&registry, &[("m1", "a", "b")]);
    let e = b.add_resource("a", None, false).unwrap_err();
    assert_eq!(e.to_string(), "the resource `a` is added twice");
    let e = b.bind_lock("m1", "outer", "nope").unwrap_err();
    assert_eq!(
        e.to_string(),
        "`m1`: there is no resource `nope` to bind the lock slot `outer` to"
    );
    let e = b.bind_lock("m1", "middle", "a").unwrap_err();
    assert_eq!(e.to_string(), "`m1` has no lock slot `middle`");
    let e = b.bind_lock("m1", "outer", "b").unwrap_err();
    assert_eq!(e.to_string(), "`m1`: the lock slot `outer` is bound twice");
    let e = b.declare_lock_order("a", "zzz", "x").unwrap_err();
    assert_eq!(e.to_string(), "there is no resource `zzz`");
}
