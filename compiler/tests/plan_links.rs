//! The run plan's links carry what the transport needs to pick its QoS: whether a
//! link may drop values (`reliability=`, else a blocking queue at the reader), and the
//! reader's `deadline=`.

use ferroc_compiler::load::{BuiltinLibrary, Options};
use ferroc_compiler::{check_model, plan, Policy};
use std::path::Path;

#[test]
fn links_are_reliable_as_the_model_says_or_as_their_queue_implies() {
    let options = Options {
        builtins: vec![BuiltinLibrary {
            name: "ferroc_std".into(),
            text: include_str!("../../components/ferroc_std.lib.xml").into(),
        }],
        ..Options::default()
    };
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("../models/rescue_robot.xml");
    let result = check_model(&model, &options, &Policy::default()).unwrap();
    let app = result.app.as_ref().unwrap();
    let (plan, _) = plan::plan(app, &result.libraries, &[]);
    let reliable = |from: &str, to: &str| {
        let c = plan
            .connections
            .iter()
            .find(|c| format!("{}/{}", c.from.0, c.from.1) == from && c.to.0.ends_with(to))
            .unwrap_or_else(|| panic!("no connection {from} → {to}"));
        c.link.as_ref().expect("between parts").reliable
    };
    // reliability="reliable", with and without a queue
    assert!(reliable("robot/vision/detector/victims", "manager"));
    assert!(reliable("robot/vision/detector/victims", "console"));
    // reliability="best-effort"
    assert!(!reliable("robot/mapping/mapper/map", "manager"));
    assert!(!reliable("robot/control/localizer/pose", "console"));
    // deadline="3s" on the battery link, none elsewhere.
    let deadline = |from: &str| {
        let c = plan
            .connections
            .iter()
            .find(|c| format!("{}/{}", c.from.0, c.from.1) == from);
        c.and_then(|c| c.link.as_ref()).and_then(|l| l.deadline)
    };
    assert_eq!(deadline("robot/drivers/base/battery_voltage"), Some(3.0));
    assert_eq!(deadline("robot/vision/detector/victims"), None);
    // Inside a part nothing travels as a link.
    assert!(plan.connections.iter().filter(|c| c.link.is_none()).count() > 0);
}
