//! The bundle of the one-AGV warehouse model (`tests/fixtures/warehouse_one_agv.xml`):
//! behaviours registered through the behaviour base, the field accessor its
//! `<convert field>` needs, and a built bundle printing exactly what `ferroc run` prints
//! (the model runs in one thread container, so its output depends only on the cycles).

mod common;

use common::{build_bundle, ferroc, tempdir};
use std::process::Command;

const MODEL: &str = "tests/fixtures/warehouse_one_agv.xml";

#[test]
fn a_built_warehouse_bundle_prints_what_ferroc_run_prints() {
    let out = tempdir("bundle_warehouse").join("b");
    let (code, _, err) = ferroc(&["bundle", MODEL, "-o", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let main = std::fs::read_to_string(out.join("parts/agv/src/main.rs")).unwrap();
    for line in [
        "registry.register_behaviour::<warehouse_fleet::FollowPath>();",
        "registry.register_behaviour::<warehouse_fleet::VelocityFusion>();",
        "registry.register::<warehouse_fleet::TaskExecutor>();",
        // Serde, as ferroc run registers it (a Logger may record it).
        "registry.register_serde::<warehouse_fleet::RobotStatus>();",
        r#"registry.register_field::<warehouse_fleet::RobotStatus, u32>("tasks_done", |v| v.tasks_done);"#,
    ] {
        assert!(main.contains(line), "{line} missing in\n{main}");
    }
    assert!(
        !main.contains("register::<warehouse_fleet::FollowPath>"),
        "{main}"
    );

    // Built into this test's target folder, which holds the dependencies already.
    let target = build_bundle(&out);

    let bundled = Command::new(target.join("debug/warehouse_one_agv-agv"))
        .env("FERROC_LOG_DIR", common::test_log_dir())
        .args(["--cycles", "3000", "-q"])
        .output()
        .unwrap();
    assert!(bundled.status.success());
    let (code, run_out, run_err) = ferroc(&["run", MODEL, "--cycles", "3000", "-q"]);
    assert_eq!(code, 0, "{run_err}");
    let bundle_out = String::from_utf8_lossy(&bundled.stdout);
    assert_eq!(bundle_out, run_out);
    assert!(run_out.contains("[agv 1] task 1: shelf at"), "{run_out}");
}
