//! The run plan lists client → service links as calls (group ports flattened away),
//! never as data connections: the runtime wires them with `connect_service`.

use ferroc_compiler::load::{BuiltinLibrary, Options};
use ferroc_compiler::{check_model, plan, Policy};
use std::path::Path;

fn pair(p: &(String, String)) -> String {
    format!("{}/{}", p.0, p.1)
}

#[test]
fn calls_through_group_ports_are_planned_as_calls() {
    let options = Options {
        builtins: vec![BuiltinLibrary {
            name: "ferroc_std".into(),
            text: include_str!("../../components/ferroc_std.lib.xml").into(),
        }],
        ..Options::default()
    };
    let model = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/deadlock_acceptance/callback_through_group_port_async.xml");
    let result = check_model(&model, &options, &Policy::default()).unwrap();
    let app = result.app.as_ref().unwrap();
    let (plan, unsupported) = plan::plan(app, &result.libraries, &[]);
    assert!(unsupported.is_empty(), "{unsupported:?}");
    let calls: Vec<(String, String)> = plan
        .calls
        .iter()
        .map(|c| (pair(&c.client), pair(&c.service)))
        .collect();
    assert_eq!(
        calls,
        [
            (
                "robot/servo/shoulder/joint/target".to_string(),
                "robot/planning/planner/target".to_string()
            ),
            (
                "robot/planning/planner/limits".to_string(),
                "robot/servo/shoulder/joint/limits".to_string()
            ),
        ]
    );
    assert!(
        plan.connections.is_empty(),
        "no data connection in this model: {:?}",
        plan.connections
    );
}
