//! The static order of thread containers, on the S101 fixture models.

use ferroc_compiler::load::{BuiltinLibrary, Options};
use ferroc_compiler::schedule::{self, StepSet};
use ferroc_compiler::{check_model, Policy};
use std::path::Path;

/// `path (kind) [set]` per step, and the broken edges as `from -> to`, per container.
fn order_of(model: &str) -> Vec<(String, Vec<String>, Vec<String>)> {
    let dir =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("checks/src/scheduling/s101_data_flow_loop");
    let options = Options {
        builtins: vec![BuiltinLibrary {
            name: "ferroc_std".into(),
            text: include_str!("../../components/ferroc_std.lib.xml").into(),
        }],
        ..Options::default()
    };
    let result = check_model(&dir.join(model), &options, &Policy::default()).unwrap();
    let app = result.app.expect("model resolves");
    let schedule = schedule::compute(&app, &result.libraries);
    schedule
        .containers
        .iter()
        .map(|c| {
            let steps = c
                .steps
                .iter()
                .map(|s| {
                    let set = match s.set {
                        StepSet::Initial => "initial",
                        StepSet::Sense => "sense",
                        StepSet::Control => "control",
                        StepSet::Other => "other",
                    };
                    format!("{} ({}) [{set}]", app.path(s.module), s.kind.as_str())
                })
                .collect();
            let broken = c
                .broken
                .iter()
                .map(|b| {
                    format!(
                        "{} -> {}{}",
                        app.path(b.from.module),
                        app.path(b.to.module),
                        if b.inhibition { " (inhibition)" } else { "" }
                    )
                })
                .collect();
            (app.path(c.thread), steps, broken)
        })
        .collect()
}

#[test]
fn sets_run_in_order_and_feedback_is_not_a_constraint() {
    let containers = order_of("silent.xml");
    let (thread, steps, broken) = &containers[0];
    assert_eq!(thread, "robot/main");
    assert_eq!(
        steps,
        &[
            // The plant reads the controller's output of the previous cycle and feeds the
            // sensor input, so it runs with sensing, before the sense step.
            "robot/main/plant (update) [sense]",
            "robot/main/avoid (sense) [sense]",
            "robot/main/avoid (control) [control]",
            // b -> a is delay="1": a runs first; e's ring leaves the container.
            "robot/main/a (update) [other]",
            "robot/main/b (update) [other]",
            "robot/main/e (update) [other]",
            // Mutual inhibition: broken at an inhibition input, by path order.
            "robot/main/retreat (update) [other]",
            "robot/main/wander (update) [other]",
        ]
    );
    assert_eq!(
        broken,
        &["robot/main/wander -> robot/main/retreat (inhibition)"]
    );
    let (thread, steps, broken) = &containers[1];
    assert_eq!(thread, "robot/slow");
    assert_eq!(steps, &["robot/slow/c (update) [other]"]);
    assert!(broken.is_empty());
}

#[test]
fn a_ring_is_broken_before_its_smallest_path() {
    let containers = order_of("fires.xml");
    let (_, steps, broken) = &containers[0];
    assert_eq!(
        steps,
        &[
            "robot/main/a (update) [other]",
            "robot/main/b (update) [other]",
            "robot/main/c (update) [other]",
        ]
    );
    assert_eq!(broken, &["robot/main/c -> robot/main/a"]);
}

#[test]
fn the_same_model_gives_the_same_order_every_time() {
    let first = order_of("fires_2.xml");
    for _ in 0..5 {
        assert_eq!(order_of("fires_2.xml"), first);
    }
}
