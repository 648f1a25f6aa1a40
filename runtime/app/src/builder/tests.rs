use super::*;
use crate::test_support::Counter;
use ferroc_module::{In, ModuleType, Out, Parameter};
use ferroc_ports::port::{ConnectOptions, CopyInputPort};

struct Gain {
    input: In<f64>,
    output: Out<f64>,
    factor: Parameter<f64>,
}
impl Module for Gain {
    fn update(&mut self) {
        let f = self.factor.get();
        self.output.publish(self.input.get() * f);
    }
}
impl ModuleType for Gain {
    const NAME: &'static str = "test.Gain";
    fn create(m: &mut Setup<'_>) -> Self {
        Gain {
            input: m.input("input").unit("m").required().build(),
            output: m.output("output").unit("m").build(),
            factor: m.param("factor").range(0.0, 10.0).default(2.0).build(),
        }
    }
}

/// Sense publishes the last command it saw; control turns the sensor value into one.
struct Loop {
    sensor: Out<f64>,
    command_in: In<f64>,
    command: Out<f64>,
    last: f64,
}
impl Module for Loop {
    fn sense(&mut self) {
        self.last = self.command_in.get();
        self.sensor.publish(self.last);
    }
    fn control(&mut self) {
        self.command.publish(self.last + 1.0);
    }
}
impl ModuleType for Loop {
    const NAME: &'static str = "test.Loop";
    const KIND: Kind = Kind::SenseControl;
    fn create(m: &mut Setup<'_>) -> Self {
        Loop {
            sensor: m.sensor_output("sensor").build(),
            command_in: m.controller_input("command_in").build(),
            command: m.controller_output("command").build(),
            last: 0.0,
        }
    }
}

struct Bomb;
impl Module for Bomb {
    fn update(&mut self) {
        panic!("boom");
    }
}
impl ModuleType for Bomb {
    const NAME: &'static str = "test.Bomb";
    fn create(_: &mut Setup<'_>) -> Self {
        Bomb
    }
}

fn registry() -> Registry {
    let mut r = Registry::new();
    r.register::<Counter>()
        .register::<Gain>()
        .register::<Loop>()
        .register::<Bomb>();
    r
}

/// Adds a module with these parameter values (shared by the Builder's test files).
pub(super) fn add(b: &mut Builder<'_>, path: &str, type_name: &str, params: &[(String, Value)]) {
    b.add_module(ModuleSpec {
        path,
        type_name,
        params,
        queues: &[],
        ports: &[],
        violations: Default::default(),
    })
    .unwrap();
}

fn thread(path: &str, steps: &[(&str, StepKind)]) -> ThreadSpec {
    ThreadSpec {
        path: path.into(),
        schedule: Schedule::Periodic(Duration::from_micros(100)),
        options: ThreadOptions::default(),
        steps: steps.iter().map(|(p, k)| (p.to_string(), *k)).collect(),
    }
}

#[test]
fn a_chain_runs_in_schedule_order_with_a_converting_connection() {
    let registry = registry();
    let mut b = Builder::new(&registry);
    add(&mut b, "count", "test.Counter", &[]);
    add(
        &mut b,
        "gain",
        "test.Gain",
        &[("factor".into(), Value::Float(0.5))],
    );
    // u32 → f64 with a scale of 10: needs a converter after `count`.
    b.connect(
        ("count", "out"),
        ("gain", "input"),
        Conversion::linear(10.0, 0.0),
        ConnectOptions::default(),
    )
    .unwrap();
    let probe = CopyInputPort::<f64>::new("probe");
    b.output("gain", "output")
        .unwrap()
        .connect(&probe.handle(), ConnectOptions::default())
        .unwrap();
    b.add_thread(thread(
        "main",
        &[("count", StepKind::Update), ("gain", StepKind::Update)],
    ))
    .unwrap();
    let mut app = b.start(Some(3)).unwrap();
    app.join();
    // Third cycle: count = 3 → 30 → × 0.5, seen in the same cycle.
    assert_eq!(probe.get(), 15.0);
}

#[test]
fn sense_and_control_steps_share_one_module() {
    let registry = registry();
    let mut b = Builder::new(&registry);
    add(&mut b, "loop", "test.Loop", &[]);
    b.connect(
        ("loop", "command"),
        ("loop", "command_in"),
        Conversion::default(),
        ConnectOptions::default(),
    )
    .unwrap();
    let probe = CopyInputPort::<f64>::new("probe");
    b.output("loop", "sensor")
        .unwrap()
        .connect(&probe.handle(), ConnectOptions::default())
        .unwrap();
    b.add_thread(thread(
        "main",
        &[("loop", StepKind::Sense), ("loop", StepKind::Control)],
    ))
    .unwrap();
    let mut app = b.start(Some(4)).unwrap();
    app.join();
    // Each control adds one to what the previous sense saw: 0, 1, 2, 3.
    assert_eq!(probe.get(), 3.0);
}

#[test]
fn a_panicking_module_is_reported_with_its_path_and_the_rest_run_on() {
    let registry = registry();
    let mut b = Builder::new(&registry);
    add(&mut b, "robot/bomb", "test.Bomb", &[]);
    add(&mut b, "robot/count", "test.Counter", &[]);
    let probe = CopyInputPort::<u32>::new("probe");
    b.output("robot/count", "out")
        .unwrap()
        .connect(&probe.handle(), ConnectOptions::default())
        .unwrap();
    b.add_thread(thread(
        "robot/main",
        &[
            ("robot/bomb", StepKind::Update),
            ("robot/count", StepKind::Update),
        ],
    ))
    .unwrap();
    let prev = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let mut app = b.start(Some(5)).unwrap();
    assert!(app.wait_timeout(Duration::from_secs(30)));
    std::panic::set_hook(prev);
    let panics = app.panics();
    app.join();
    assert_eq!(probe.get(), 5);
    assert_eq!(panics.len(), 1);
    assert!(
        panics[0].contains("`robot/bomb:update` panicked: boom"),
        "{panics:?}"
    );
}

#[test]
fn mistakes_are_error_values() {
    let registry = registry();
    let mut b = Builder::new(&registry);
    let err = b
        .add_module(ModuleSpec {
            path: "x",
            type_name: "test.Nope",
            params: &[],
            queues: &[],
            ports: &[],
            violations: Default::default(),
        })
        .unwrap_err();
    assert_eq!(
        err.to_string(),
        "`x`: the module type `test.Nope` is not registered in this binary"
    );
    let err = b
        .add_module(ModuleSpec {
            path: "g",
            type_name: "test.Gain",
            params: &[
                ("factor".into(), Value::Float(11.0)),
                ("gian".into(), Value::Float(1.0)),
            ],
            queues: &[],
            ports: &[],
            violations: Default::default(),
        })
        .unwrap_err();
    assert_eq!(
        err.to_string(),
        "`g` could not be created: parameter `factor`: 11 is outside the allowed range \
         0..=10; the type has no parameter `gian`"
    );
    add(&mut b, "g", "test.Gain", &[]);
    add(&mut b, "c", "test.Counter", &[]);
    let err = b
        .connect(
            ("c", "output"),
            ("g", "input"),
            Conversion::default(),
            ConnectOptions::default(),
        )
        .unwrap_err();
    assert_eq!(err.to_string(), "`c` has no output port `output`");
    add(&mut b, "l", "test.Loop", &[]);
    let err = b
        .add_thread(thread("t", &[("l", StepKind::Update)]))
        .unwrap_err();
    assert_eq!(
        err.to_string(),
        "`l` is a sense-control module and has no Update step"
    );
    b.add_thread(thread("t", &[("g", StepKind::Update)]))
        .unwrap();
    let err = b
        .add_thread(thread("u", &[("g", StepKind::Update)]))
        .unwrap_err();
    assert_eq!(
        err.to_string(),
        "`g` is executed by two thread containers: `t` and `u`"
    );
    let err = b.start(Some(1)).err().unwrap();
    assert_eq!(
        err.to_string(),
        "`c` is not executed by any thread container"
    );
}

#[test]
fn parameters_change_while_running() {
    let registry = registry();
    let mut b = Builder::new(&registry);
    add(&mut b, "g", "test.Gain", &[]);
    b.add_thread(thread("t", &[("g", StepKind::Update)]))
        .unwrap();
    let app = b.start(None).unwrap();
    assert!(app.set_parameter("g", "factor", &Value::Float(3.0)).is_ok());
    assert_eq!(
        app.set_parameter("g", "factor", &Value::Float(-1.0))
            .unwrap_err(),
        "-1 is outside the allowed range 0..=10"
    );
    assert!(app.set_parameter("g", "gain", &Value::Float(1.0)).is_err());
    app.stop();
}

#[test]
fn the_registry_reports_the_declared_interface() {
    let i = registry().interface("test.Gain").unwrap();
    assert_eq!(i.kind, Kind::Plain);
    let ports: Vec<_> = i
        .ports
        .iter()
        .map(|p| {
            (
                p.name.as_str(),
                p.dir,
                p.model_type.as_str(),
                p.unit.as_deref(),
                p.required,
            )
        })
        .collect();
    use ferroc_module::Direction::{In, Out};
    assert_eq!(
        ports,
        [
            ("input", In, "f64", Some("m"), true),
            ("output", Out, "f64", Some("m"), false)
        ]
    );
    assert_eq!(i.params[0].default.as_deref(), Some("2"));
    assert_eq!((i.params[0].min, i.params[0].max), (Some(0.0), Some(10.0)));
    assert!(registry().interface("test.Nope").is_none());
}

#[test]
fn a_data_triggered_container_is_not_woken_by_its_own_outputs() {
    let registry = registry();
    let mut b = Builder::new(&registry);
    add(&mut b, "first", "test.Gain", &[]);
    add(&mut b, "second", "test.Gain", &[]);
    b.connect(
        ("first", "output"),
        ("second", "input"),
        Conversion::default(),
        ConnectOptions::default(),
    )
    .unwrap();
    let source = ferroc_ports::port::CopyOutputPort::<f64>::new("source");
    source
        .handle()
        .connect(
            b.input("first", "input").unwrap(),
            ConnectOptions::default(),
        )
        .unwrap();
    let mut spec = thread(
        "on_data",
        &[("first", StepKind::Update), ("second", StepKind::Update)],
    );
    spec.schedule = Schedule::Data;
    b.add_thread(spec).unwrap();
    let app = b.start(None).unwrap();
    source.publish(1.0);
    let stats = app.stats().remove(0);
    while stats.cycles() == 0 {
        std::thread::sleep(Duration::from_millis(1));
    }
    // `first` publishes into `second` every cycle; were that a wakeup, the container
    // would cycle forever. It must stay at one cycle per outside delivery.
    std::thread::sleep(Duration::from_millis(100));
    assert_eq!(stats.cycles(), 1);
    source.publish(2.0);
    while stats.cycles() == 1 {
        std::thread::sleep(Duration::from_millis(1));
    }
    std::thread::sleep(Duration::from_millis(100));
    assert_eq!(stats.cycles(), 2);
    app.stop();
}

/// `count → gain/input` and `count → gain/param/factor`: gain = count · count.
fn squares(cycles: u64) -> f64 {
    let registry = registry();
    let mut b = Builder::new(&registry);
    add(&mut b, "count", "test.Counter", &[]);
    add(&mut b, "gain", "test.Gain", &[]);
    b.connect(
        ("count", "out"),
        ("gain", "input"),
        Conversion::default(),
        ConnectOptions::default(),
    )
    .unwrap();
    b.connect_param(("count", "out"), ("gain", "factor"), Conversion::default())
        .unwrap();
    let probe = CopyInputPort::<f64>::new("probe");
    b.output("gain", "output")
        .unwrap()
        .connect(&probe.handle(), ConnectOptions::default())
        .unwrap();
    b.add_thread(thread(
        "main",
        &[("count", StepKind::Update), ("gain", StepKind::Update)],
    ))
    .unwrap();
    let mut app = b.start(Some(cycles)).unwrap();
    app.join();
    probe.get()
}

#[test]
fn a_port_drives_a_parameter_in_the_same_cycle_within_its_range() {
    assert_eq!(squares(3), 9.0);
    // factor's range is 0..10: 11 and 12 are refused and it stays 10.
    assert_eq!(squares(12), 120.0);
}

#[test]
fn driving_a_missing_or_text_parameter_is_an_error_value() {
    let registry = registry();
    let mut b = Builder::new(&registry);
    add(&mut b, "count", "test.Counter", &[]);
    add(&mut b, "gain", "test.Gain", &[]);
    assert!(matches!(
        b.connect_param(("count", "out"), ("gain", "gain"), Conversion::default()),
        Err(BuildError::Create { .. })
    ));
    assert!(matches!(
        b.connect_param(
            ("count", "nothing"),
            ("gain", "factor"),
            Conversion::default()
        ),
        Err(BuildError::UnknownPort { .. })
    ));
}

#[test]
fn a_starved_data_triggered_container_does_not_hold_up_the_cycle_limit() {
    let registry = registry();
    let mut b = Builder::new(&registry);
    add(&mut b, "clocked", "test.Counter", &[]);
    add(&mut b, "starved", "test.Counter", &[]);
    b.add_thread(thread("clock", &[("clocked", StepKind::Update)]))
        .unwrap();
    let mut data = thread("data", &[("starved", StepKind::Update)]);
    data.schedule = Schedule::Data;
    b.add_thread(data).unwrap();
    let mut app = b.start(Some(3)).unwrap();
    // Nothing ever feeds `starved`: the application ends with the clocked container.
    assert!(app.wait_timeout(Duration::from_secs(10)));
    app.stop();
    app.join();
    let cycles: Vec<u64> = app.status().iter().map(|s| s.cycles).collect();
    assert_eq!(cycles, [3, 0]);
}
