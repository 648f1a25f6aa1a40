//! Services wired by the Builder: by name, typed, waking their server's container.

use super::tests::add;
use super::*;
use ferroc_module::{ModuleType, Out, ServiceInfo};
use ferroc_ports::port::{ConnectOptions, CopyInputPort};
use ferroc_ports::service::{CallError, ClientPort, Executes, ServicePort};
use std::time::Instant;

/// Answers `square` (x → x²) in its step.
struct Server {
    square: ServicePort<i64, i64>,
}
impl Module for Server {
    fn update(&mut self) {
        self.square.serve_pending(|x| x * x);
    }
}
impl ModuleType for Server {
    const NAME: &'static str = "test.Server";
    fn create(m: &mut Setup<'_>) -> Self {
        Server {
            square: m.service("square").doc("x²").build(),
        }
    }
}

/// Answers `double` inline on its callers' threads.
struct Inline {
    _double: ServicePort<i64, i64>,
}
impl Module for Inline {}
impl ModuleType for Inline {
    const NAME: &'static str = "test.Inline";
    fn create(m: &mut Setup<'_>) -> Self {
        Inline {
            _double: m.service("double").executed_by_caller(|x: i64| 2 * x),
        }
    }
}

/// Calls `ask` with 1, 2, 3, … and publishes the answer (-1: not connected, -2: other
/// errors).
struct Caller {
    ask: ClientPort<i64, i64>,
    answer: Out<i64>,
    n: i64,
}
impl Module for Caller {
    fn update(&mut self) {
        self.n += 1;
        let answer = match self.ask.call(self.n) {
            Ok(x) => x,
            Err(CallError::NotConnected) => -1,
            Err(_) => -2,
        };
        self.answer.publish(answer);
    }
}
impl ModuleType for Caller {
    const NAME: &'static str = "test.Caller";
    fn create(m: &mut Setup<'_>) -> Self {
        Caller {
            ask: m.client("ask").timeout(Duration::from_secs(5)).build(),
            answer: m.output("answer").build(),
            n: 0,
        }
    }
}

/// A client of other types than the services above.
struct Mismatched {
    _ask: ClientPort<f64, bool>,
}
impl Module for Mismatched {}
impl ModuleType for Mismatched {
    const NAME: &'static str = "test.Mismatched";
    fn create(m: &mut Setup<'_>) -> Self {
        Mismatched {
            _ask: m.client("ask").build(),
        }
    }
}

fn registry() -> Registry {
    let mut r = Registry::new();
    r.register::<Server>()
        .register::<Inline>()
        .register::<Caller>()
        .register::<Mismatched>();
    r
}

fn thread(path: &str, schedule: Schedule, module: &str) -> ThreadSpec {
    ThreadSpec {
        path: path.into(),
        schedule,
        options: ThreadOptions::default(),
        steps: vec![(module.into(), StepKind::Update)],
    }
}

/// `caller` (periodic, with a probe on its answers) and a service of `server_type`.
fn caller_and(server_type: &str, service: &str, connect: bool) -> (StopOnDrop, CopyInputPort<i64>) {
    let registry = registry();
    let mut b = Builder::new(&registry);
    add(&mut b, "caller", "test.Caller", &[]);
    add(&mut b, "server", server_type, &[]);
    if connect {
        b.connect_service(("caller", "ask"), ("server", service))
            .unwrap();
    }
    let probe = CopyInputPort::<i64>::new("probe");
    b.output("caller", "answer")
        .unwrap()
        .connect(&probe.handle(), ConnectOptions::default())
        .unwrap();
    let period = Schedule::Periodic(Duration::from_micros(200));
    b.add_thread(thread("a", period, "caller")).unwrap();
    b.add_thread(thread("b", Schedule::Data, "server")).unwrap();
    (StopOnDrop(b.start(None).unwrap()), probe)
}

/// Stops the application when dropped, so a failing assertion cannot leave threads.
struct StopOnDrop(RunningApp);
impl Drop for StopOnDrop {
    fn drop(&mut self) {
        self.0.stop();
        self.0.join();
    }
}

/// Waits (bounded) until the probe shows `value`; the last value seen.
fn wait_for(probe: &CopyInputPort<i64>, done: impl Fn(i64) -> bool) -> i64 {
    let deadline = Instant::now() + Duration::from_secs(20);
    while !done(probe.get()) && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(1));
    }
    probe.get()
}

#[test]
fn a_call_wakes_the_data_triggered_server_which_answers_in_its_step() {
    let (_app, probe) = caller_and("test.Server", "square", true);
    // Answers are n² for n = 1, 2, 3, …: 9 means three calls were answered in order.
    let seen = wait_for(&probe, |x| x >= 9);
    let root = (seen as f64).sqrt() as i64;
    assert_eq!(root * root, seen, "every answer is a square: {seen}");
}

#[test]
fn a_service_executed_by_the_caller_answers_inline() {
    let (_app, probe) = caller_and("test.Inline", "double", true);
    let seen = wait_for(&probe, |x| x >= 6);
    assert_eq!(seen % 2, 0, "every answer is doubled: {seen}");
}

#[test]
fn an_unconnected_client_gets_an_error_value_not_a_hang() {
    let (_app, probe) = caller_and("test.Server", "square", false);
    assert_eq!(wait_for(&probe, |x| x == -1), -1);
}

#[test]
fn wiring_mistakes_are_error_values() {
    let registry = registry();
    let mut b = Builder::new(&registry);
    add(&mut b, "mismatched", "test.Mismatched", &[]);
    add(&mut b, "server", "test.Server", &[]);
    add(&mut b, "caller", "test.Caller", &[]);
    let Err(BuildError::Connect(why)) =
        b.connect_service(("mismatched", "ask"), ("server", "square"))
    else {
        panic!("a client of other types must not connect");
    };
    assert!(
        why.contains("request and response types must be the same"),
        "{why}"
    );
    assert!(
        matches!(
            b.connect_service(("caller", "ask"), ("server", "nothing")),
            Err(BuildError::UnknownPort {
                wanted: "service",
                ..
            })
        ),
        "an unknown service is named"
    );
    b.connect_service(("caller", "ask"), ("server", "square"))
        .unwrap();
    let Err(BuildError::Connect(why)) = b.connect_service(("caller", "ask"), ("server", "square"))
    else {
        panic!("a client calls one service");
    };
    assert!(why.contains("already connected"), "{why}");
}

#[test]
fn the_interface_lists_services_and_clients() {
    let registry = registry();
    let server = registry.interface("test.Server").unwrap();
    assert_eq!(
        server.services,
        vec![ServiceInfo {
            name: "square".into(),
            client: false,
            request: "i64".into(),
            response: "i64".into(),
            executes: Executes::Server,
            timeout: None,
            doc: Some("x²".into()),
        }]
    );
    let inline = registry.interface("test.Inline").unwrap();
    assert_eq!(inline.services[0].executes, Executes::Caller);
    let caller = registry.interface("test.Caller").unwrap();
    assert!(caller.services[0].client);
    assert_eq!(caller.services[0].timeout, Some(Duration::from_secs(5)));
}

/// A service named like one of the module's ports.
struct Clash {
    _out: Out<i64>,
    _square: ServicePort<i64, i64>,
}
impl Module for Clash {}
impl ModuleType for Clash {
    const NAME: &'static str = "test.Clash";
    fn create(m: &mut Setup<'_>) -> Self {
        Clash {
            _out: m.output("square").build(),
            _square: m.service("square").build(),
        }
    }
}

#[test]
fn ports_services_and_clients_share_one_namespace() {
    let mut registry = registry();
    registry.register::<Clash>();
    let mut b = Builder::new(&registry);
    let e = b
        .add_module(ModuleSpec {
            path: "clash",
            type_name: "test.Clash",
            params: &[],
            queues: &[],
            ports: &[],
            violations: Default::default(),
        })
        .unwrap_err();
    assert!(
        e.to_string()
            .contains("the port `square` is declared twice"),
        "{e}"
    );
    // Distinct names are fine (the silent case).
    add(&mut b, "server", "test.Server", &[]);
}
