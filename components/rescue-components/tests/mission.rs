//! The whole rescue robot and station in one continuous thread container, every module
//! stepped once per cycle in a fixed order: lockstep, so the run is exactly
//! reproducible (unlike the model, whose thread containers run on wall-clock time).
//! The planner's velocity reaches the base field by field (`<convert field>`), as in
//! the model.

// A scenario reads as one story from start to end; the function-length rule is for
// the code under test.
#![allow(clippy::too_many_lines)]

use ferroc_runtime::builder::{
    Builder, Conversion, ModuleSpec, Registry, Schedule, StepKind, ThreadSpec,
};
use ferroc_runtime::container::ThreadOptions;
use ferroc_runtime::module::{In, Module, ModuleType, Setup, Value};
use ferroc_runtime::port::{ConnectOptions, QueueConfig};
use rescue_components::{Pose2D, VictimList};
use std::sync::Mutex;
use std::time::Duration;

/// What the probe saw in each cycle: pose, victims, state.
static SEEN: Mutex<Vec<(Pose2D, VictimList, String)>> = Mutex::new(Vec::new());

struct Probe {
    pose: In<Pose2D>,
    victims: In<VictimList>,
    state: In<String>,
}

impl ModuleType for Probe {
    const NAME: &'static str = "test.Probe";
    fn create(m: &mut Setup<'_>) -> Self {
        Probe {
            pose: m.input("pose").build(),
            victims: m.input("victims").build(),
            state: m.input("state").build(),
        }
    }
}

impl Module for Probe {
    fn update(&mut self) {
        let seen = (
            self.pose.get(),
            VictimList::clone(&self.victims.get()),
            String::clone(&self.state.get()),
        );
        SEEN.lock().unwrap().push(seen);
    }
}

/// Parameter values of one module.
type Params = Vec<(String, Value)>;

fn text(s: &str) -> Value {
    Value::Text(s.to_string())
}

/// Runs `cycles` lockstep cycles (25 ms of model time each).
fn run(cycles: u64, report: &std::path::Path) {
    let mut registry = Registry::new();
    rescue_components::register(&mut registry);
    registry.register::<Probe>();
    let mut b = Builder::new(&registry);
    let modules: Vec<(&str, &str, Params)> = vec![
        (
            "laser",
            "rescue.LaserDriver",
            vec![("device".into(), text("sim"))],
        ),
        (
            "camera",
            "rescue.Camera",
            vec![
                ("device".into(), text("sim")),
                ("exposure".into(), Value::Float(8.0)),
            ],
        ),
        (
            "base",
            "rescue.BaseDriver",
            vec![
                ("port".into(), text("sim")),
                ("max_speed".into(), Value::Float(0.8)),
                ("wheel_base".into(), Value::Float(0.42)),
            ],
        ),
        (
            "localizer",
            "rescue.Localizer",
            vec![("particles".into(), Value::Int(800))],
        ),
        (
            "mapper",
            "rescue.Mapper",
            vec![
                ("size".into(), Value::Float(30.0)),
                (
                    "publish_period".into(),
                    Value::Duration(Duration::from_secs(2)),
                ),
            ],
        ),
        (
            "detector",
            "rescue.VictimDetector",
            vec![
                ("model_file".into(), text("none")),
                ("merge_distance".into(), Value::Float(0.4)),
            ],
        ),
        (
            "planner",
            "rescue.PathPlanner",
            vec![
                ("max_speed".into(), Value::Float(0.5)),
                ("robot_radius".into(), Value::Float(0.32)),
            ],
        ),
        (
            "context",
            "rescue.MissionContext",
            vec![("initial_context".into(), text("explore"))],
        ),
        (
            "manager",
            "rescue.MissionManager",
            vec![
                ("mission_name".into(), text("lockstep")),
                ("frontier_min_size".into(), Value::Float(0.8)),
                ("report_file".into(), text(report.to_str().unwrap())),
            ],
        ),
        (
            "console",
            "rescue.OperatorConsole",
            vec![
                ("title".into(), text("lockstep")),
                ("refresh".into(), Value::Float(40.0)),
            ],
        ),
        ("probe", "test.Probe", vec![]),
    ];
    let queued = |port: &str| vec![(port.to_string(), QueueConfig::new(16))];
    for (name, ty, params) in &modules {
        let queues = match *name {
            "manager" => queued("victims"),
            "mapper" => queued("scan"),
            "context" => queued("command"),
            "planner" => queued("goal"),
            _ => Vec::new(),
        };
        b.add_module(ModuleSpec {
            path: name,
            type_name: ty,
            params,
            queues: &queues,
            ports: &[],
            violations: Default::default(),
        })
        .unwrap();
    }
    b.add_resource("map_lock", None, false).unwrap();
    b.bind_lock("planner", "grid", "map_lock").unwrap();
    for (from, to) in [
        ("laser/scan", "localizer/scan"),
        ("base/odometry", "localizer/odometry"),
        ("laser/scan", "mapper/scan"),
        ("localizer/pose", "mapper/pose"),
        ("localizer/pose", "planner/pose"),
        ("mapper/map", "planner/map"),
        ("laser/scan", "planner/scan"),
        ("camera/image", "detector/image"),
        ("localizer/pose", "detector/pose"),
        ("laser/scan", "detector/scan"),
        ("detector/victims", "context/victims"),
        ("base/battery_voltage", "context/battery_voltage"),
        ("detector/victims", "manager/victims"),
        ("detector/victims", "console/victims"),
        ("mapper/map", "manager/map"),
        ("mapper/map", "console/map"),
        ("localizer/pose", "manager/pose"),
        ("localizer/pose", "console/pose"),
        ("context/state", "console/robot_state"),
        ("base/battery_voltage", "console/battery_voltage"),
        ("manager/goal", "planner/goal"),
        ("manager/command", "context/command"),
        ("console/command", "manager/operator_command"),
        ("localizer/pose", "probe/pose"),
        ("detector/victims", "probe/victims"),
        ("context/state", "probe/state"),
    ] {
        let (a, b_) = (from.split_once('/').unwrap(), to.split_once('/').unwrap());
        b.connect(a, b_, Conversion::default(), ConnectOptions::default())
            .unwrap_or_else(|e| panic!("{from} → {to}: {e}"));
    }
    for (field, input) in [("linear", "velocity"), ("angular", "angular_velocity")] {
        let conversion = Conversion::default().field(field);
        b.connect(
            ("planner", "cmd"),
            ("base", input),
            conversion,
            ConnectOptions::default(),
        )
        .unwrap_or_else(|e| panic!("planner/cmd.{field} → base/{input}: {e}"));
    }
    let step = |m: &str, k: StepKind| (m.to_string(), k);
    b.add_thread(ThreadSpec {
        path: "all".into(),
        schedule: Schedule::Continuous,
        options: ThreadOptions::default(),
        steps: vec![
            step("base", StepKind::Sense),
            step("laser", StepKind::Update),
            step("camera", StepKind::Update),
            step("localizer", StepKind::Sense),
            step("mapper", StepKind::Update),
            step("detector", StepKind::Update),
            step("context", StepKind::Update),
            step("manager", StepKind::Update),
            step("console", StepKind::Update),
            step("planner", StepKind::Update),
            step("localizer", StepKind::Control),
            step("base", StepKind::Control),
            step("probe", StepKind::Update),
        ],
    })
    .unwrap();
    let app = b.start(Some(cycles)).unwrap();
    assert!(app.wait_timeout(Duration::from_secs(600)), "did not finish");
    assert!(app.panics().is_empty(), "{:?}", app.panics());
}

#[test]
fn the_robot_explores_the_building_and_finds_every_victim() {
    let report = std::env::temp_dir().join(format!("rescue-lockstep-{}.json", std::process::id()));
    // Three minutes of model time.
    run(7200, &report);
    let seen = SEEN.lock().unwrap();
    assert_eq!(seen.len(), 7200);
    let (pose, victims, state) = seen.last().unwrap().clone();
    let truth = [(0.0, 1.2), (4.0, -3.5), (8.5, 3.5)];
    for (x, y) in truth {
        let found = victims
            .victims
            .iter()
            .find(|v| (v.x - x).hypot(v.y - y) < 0.3);
        assert!(
            found.is_some(),
            "victim at ({x}, {y}) not found: {victims:?}"
        );
    }
    assert_eq!(victims.victims.len(), 3, "{victims:?}");
    assert!(
        victims.victims.iter().all(|v| v.confidence >= 0.9),
        "{victims:?}"
    );
    // The report on the station holds the same list (JSON keeps 15 digits).
    let written: VictimList =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(written.victims.len(), 3);
    for (w, v) in written.victims.iter().zip(&victims.victims) {
        assert_eq!((w.id, w.confidence), (v.id, v.confidence));
        assert!(
            (w.x - v.x).abs() < 1e-9 && (w.y - v.y).abs() < 1e-9,
            "{w:?}"
        );
    }
    let _ = std::fs::remove_file(&report);
    // Every reachable floor searched, the robot went home (within the planner's goal
    // tolerance of 0.2 m, plus the localizer's drift).
    assert_eq!(state, "return_home");
    let (x, y, _) = rescue_components::START;
    assert!((pose.x - x).hypot(pose.y - y) < 0.3, "{pose:?}");
    // It approached each victim when first seen: the context switched to approaching
    // and back to exploring three times.
    let switches = seen
        .windows(2)
        .filter(|w| w[0].2 == "explore" && w[1].2 == "approach_victim")
        .count();
    assert_eq!(switches, 3);
}
