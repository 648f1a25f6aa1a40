use super::*;
use crate::builder::{Builder, Lockstep, ModuleSpec, Registry, Schedule, StartOptions};
use crate::builder::{StepKind, ThreadSpec};
use crate::test_support::Counter;
use ferroc_exec::ThreadOptions;
use ferroc_module::{In, Module, ModuleType, Out, Parameter, Setup};
use ferroc_ports::port::ConnectOptions;
use std::time::Duration;

struct Gain {
    input: In<u32>,
    output: Out<f64>,
    names: Out<Vec<f64>>,
    factor: Parameter<f64>,
}
impl Module for Gain {
    fn update(&mut self) {
        let f = self.factor.get();
        let x = f64::from(self.input.get()) * f;
        self.output.publish(x);
        self.names.publish(vec![x, f]);
    }
}
impl ModuleType for Gain {
    const NAME: &'static str = "test.Gain";
    fn create(m: &mut Setup<'_>) -> Self {
        Gain {
            input: m.input("input").required().build(),
            output: m.output("output").unit("m").build(),
            names: m.output("pair").build(),
            factor: m
                .param("factor")
                .unit("m")
                .range(0.0, 10.0)
                .default(2.0)
                .build(),
        }
    }
}

fn registry() -> Registry {
    let mut r = Registry::new();
    r.register::<Counter>().register::<Gain>();
    r
}

fn built(r: &Registry) -> Builder<'_> {
    let mut b = Builder::new(r);
    for (path, ty) in [("robot/count", "test.Counter"), ("robot/gain", "test.Gain")] {
        b.add_module(ModuleSpec {
            path,
            type_name: ty,
            params: &[],
            queues: &[],
            ports: &[],
            violations: Default::default(),
        })
        .unwrap();
    }
    b.connect(
        ("robot/count", "out"),
        ("robot/gain", "input"),
        Default::default(),
        ConnectOptions::default(),
    )
    .unwrap();
    b.add_thread(ThreadSpec {
        path: "robot/control".into(),
        schedule: Schedule::Periodic(Duration::from_millis(10)),
        options: ThreadOptions::default(),
        steps: vec![
            ("robot/count".into(), StepKind::Update),
            ("robot/gain".into(), StepKind::Update),
        ],
    })
    .unwrap();
    b
}

/// Runs `cycles` instants in lockstep (exact) and returns the inspector.
fn run(r: &Registry, cycles: u64) -> Inspector {
    let mut b = built(r);
    let catalogue = b.inspection();
    let mut app = b
        .start_with(StartOptions {
            limit: Some(cycles),
            lockstep: Some(Lockstep {
                periods: Vec::new(),
                until: None,
            }),
            network: None,
        })
        .unwrap();
    assert!(app.wait_timeout(Duration::from_secs(20)), "lockstep ends");
    app.join();
    let inspector = Inspector::new(catalogue, app.stats(), r.values());
    inspector.add_connection(("robot/count", "out"), ("robot/gain", "input"));
    inspector.set_origin(
        "robot/gain",
        Origin {
            part: "robot".into(),
            source: Some("m.xml:3:5".into()),
        },
    );
    inspector
}

#[test]
fn values_are_the_latest_published_in_serde_form() {
    let r = registry();
    let i = run(&r, 5);
    let v = i.value("robot/count", "out").unwrap();
    assert_eq!((v.value.as_u64(), v.published), (Some(5), true));
    assert_eq!(v.r#type, "u32");
    let g = i.value("robot/gain", "output").unwrap();
    assert_eq!(g.value.as_f64(), Some(10.0));
    assert_eq!(g.unit.as_deref(), Some("m"));
    let pair = i.value("robot/gain", "pair").unwrap();
    assert_eq!(pair.value, serde_json::json!([10.0, 2.0]), "a pooled value");
    // An input shows what its writer published; reading again gives the same (the
    // probe was disconnected, not left behind).
    let input = i.value("robot/gain", "input").unwrap();
    assert_eq!(
        (input.port.as_str(), input.value.as_u64()),
        ("robot/count/out", Some(5))
    );
    assert_eq!(
        i.value("robot/count", "out").unwrap().value.as_u64(),
        Some(5)
    );
}

#[test]
fn an_output_never_published_says_so() {
    let r = registry();
    let mut b = built(&r);
    let i = Inspector::new(b.inspection(), Vec::new(), r.values());
    let v = i.value("robot/count", "out").unwrap();
    assert_eq!((v.published, v.value.as_u64()), (false, Some(0)));
}

#[test]
fn unknown_names_are_errors_that_list_what_exists() {
    let r = registry();
    let i = run(&r, 1);
    let e = i.value("robot/count", "nope").unwrap_err();
    assert!(e.contains("has no port `nope`") && e.contains("out"), "{e}");
    let e = i.value("robot/none", "out").unwrap_err();
    assert!(e.contains("no module `robot/none`"), "{e}");
    let e = i.param("robot/gain", "gain").unwrap_err();
    assert!(e.contains("its parameters: factor"), "{e}");
    assert_eq!(i.split("robot/gain/factor"), Ok(("robot/gain", "factor")));
    assert!(i.split("robot/gain").is_err() && i.split("robot/gain/").is_err());
    // Port names with slashes (derived activities, fusion channels) stay whole.
    assert_eq!(
        i.split("robot/gain/activity/emergency"),
        Ok(("robot/gain", "activity/emergency"))
    );
    assert!(i.split("robot/none/activity/emergency").is_err());
}

#[test]
fn a_parameter_change_is_checked_before_it_is_applied() {
    let r = registry();
    let i = run(&r, 2);
    let p = i.param("robot/gain", "factor").unwrap();
    assert_eq!(
        (p.value.as_str(), p.unit.as_deref(), p.min, p.max),
        ("2", Some("m"), Some(0.0), Some(10.0))
    );
    let e = i
        .set_param("robot/gain", "factor", &Value::Float(20.0))
        .unwrap_err();
    assert!(
        e.contains("keeps its value") && e.contains("outside the allowed range"),
        "{e}"
    );
    let e = i
        .set_param("robot/gain", "factor", &Value::Text("x".into()))
        .unwrap_err();
    assert!(e.contains("expected a number"), "{e}");
    assert_eq!(i.param("robot/gain", "factor").unwrap().value, "2");
    let set = i
        .set_param("robot/gain", "factor", &Value::Float(3.5))
        .unwrap();
    assert_eq!(set.value, "3.5");
}

#[test]
fn the_tree_has_kinds_sources_containers_and_connections() {
    let r = registry();
    let i = run(&r, 3);
    let t = i.tree(Some("robot"));
    assert_eq!(t.modules.len(), 2);
    let gain = &t.modules[1];
    assert_eq!(
        (
            gain.r#type.as_str(),
            gain.kind.as_str(),
            gain.source.as_deref()
        ),
        ("test.Gain", "plain", Some("m.xml:3:5"))
    );
    assert_eq!(gain.container.as_deref(), Some("robot/control"));
    let input = gain.ports.iter().find(|p| p.name == "input").unwrap();
    assert_eq!(input.from, vec!["robot/count/out".to_string()]);
    assert_eq!(t.containers[0].modules, ["robot/count", "robot/gain"]);
    assert!(i.tree(Some("station")).modules.is_empty(), "another part");
    assert_eq!(i.parts().into_iter().collect::<Vec<_>>(), ["robot"]);
    let c = &i.containers(None)[0];
    assert_eq!(
        (c.path.as_str(), c.cycles, c.steps.len()),
        ("robot/control", 3, 2)
    );
    assert_eq!(c.steps[0].runs, 3);
    assert!(i.links(None).is_empty(), "no links between parts here");
    assert!(i.activities(None).is_empty(), "no behaviours here");
}

/// Issue 27, item 5: an edit that removed every module left the program answering no
/// key at all (its parts came from its modules), so the model could be neither saved
/// nor edited back. The part stays inspectable: its tree is empty, its container
/// still shows.
#[test]
fn a_part_whose_last_module_is_removed_is_still_served() {
    let r = registry();
    let i = run(&r, 3);
    i.rebuild(Catalogue {
        modules: Vec::new(),
        threads: vec![("robot/control".into(), Vec::new())],
        ros2: Vec::new(),
        hub: None,
    });
    assert_eq!(i.parts().into_iter().collect::<Vec<_>>(), ["robot"]);
    let t = i.tree(Some("robot"));
    assert!(t.modules.is_empty());
    assert_eq!(t.containers[0].path, "robot/control");
    assert_eq!(i.containers(Some("robot"))[0].path, "robot/control");
    // Even with no container left in the catalogue, a part once served stays.
    i.rebuild(Catalogue {
        modules: Vec::new(),
        threads: Vec::new(),
        ros2: Vec::new(),
        hub: None,
    });
    assert_eq!(i.parts().into_iter().collect::<Vec<_>>(), ["robot"]);
}
