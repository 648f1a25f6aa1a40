//! The server and the client over real Zenoh sessions on loopback: answers, checked
//! and authenticated changes, and malformed requests answered with errors while the
//! server keeps serving.

use ferroc_inspect::client::Client;
use ferroc_inspect::request::{key, What};
use ferroc_inspect::server::{self, Server};
use ferroc_runtime::builder::{Builder, Lockstep, ModuleSpec, Registry, Schedule, StartOptions};
use ferroc_runtime::builder::{StepKind, ThreadSpec};
use ferroc_runtime::container::ThreadOptions;
use ferroc_runtime::inspect::view::{ParamView, PortValue, Tree};
use ferroc_runtime::inspect::Inspector;
use ferroc_runtime::module::{Module, ModuleType, Out, Parameter, Setup, Value};
use std::sync::Arc;
use std::time::Duration;

struct Speed {
    out: Out<f64>,
    value: Parameter<f64>,
}
impl Module for Speed {
    fn update(&mut self) {
        let v = self.value.get();
        self.out.publish(v);
    }
}
impl ModuleType for Speed {
    const NAME: &'static str = "test.Speed";
    fn create(m: &mut Setup<'_>) -> Self {
        Speed {
            out: m.output("out").unit("m/s").build(),
            value: m
                .param("value")
                .unit("m/s")
                .range(0.0, 2.0)
                .default(0.5)
                .build(),
        }
    }
}

const TOKEN: &str = "0123456789abcdef0123456789abcdef";

/// Runs 3 lockstep instants of one module and serves it on a free loopback port.
fn serve() -> (Server, String) {
    let mut registry = Registry::new();
    registry.register::<Speed>();
    let mut b = Builder::new(&registry);
    b.add_module(ModuleSpec {
        path: "robot/speed",
        type_name: "test.Speed",
        params: &[],
        queues: &[],
        ports: &[],
        violations: Default::default(),
    })
    .unwrap();
    b.add_thread(ThreadSpec {
        path: "robot/main".into(),
        schedule: Schedule::Periodic(Duration::from_millis(10)),
        options: ThreadOptions::default(),
        steps: vec![("robot/speed".into(), StepKind::Update)],
    })
    .unwrap();
    let catalogue = b.inspection();
    let mut app = b
        .start_with(StartOptions {
            limit: Some(3),
            lockstep: Some(Lockstep {
                periods: Vec::new(),
                until: None,
            }),
            network: None,
        })
        .unwrap();
    assert!(app.wait_timeout(Duration::from_secs(20)));
    app.join();
    let inspector = Inspector::new(catalogue, app.stats(), registry.values());
    let port = ferroc_testkit::free_port();
    let address = format!("127.0.0.1:{port}");
    let config = ferroc_inspect::config::server(&address).unwrap();
    // Numbers only, without units: the runner's parser (with units) is tested in host.
    let parse = Box::new(|_: &ParamView, text: &str| {
        text.trim()
            .parse::<f64>()
            .map(Value::Float)
            .map_err(|e| format!("`{text}`: {e}"))
    });
    let server = server::serve(config, "app", Arc::new(inspector), TOKEN.into(), parse).unwrap();
    (server, address)
}

fn error(client: &Client, key: &str, payload: Option<&[u8]>) -> String {
    let answers = client.ask(key, payload.map(<[u8]>::to_vec)).unwrap();
    assert_eq!(answers.len(), 1, "{key}: {answers:?}");
    answers[0].result.clone().unwrap_err()
}

#[test]
fn a_client_reads_the_tree_and_values_and_changes_with_the_token_only() {
    let (_server, address) = serve();
    let client = Client::connect(&[address]).unwrap();
    let tree: Tree = client.one("app", "robot", &What::Tree).unwrap();
    assert_eq!(tree.modules[0].path, "robot/speed");
    assert_eq!(tree.containers[0].path, "robot/main");
    // Every application and part: one answer, from this part.
    let all = client.ask(&key("*", "*", &What::Tree), None).unwrap();
    assert_eq!(all.len(), 1);
    assert_eq!(all[0].app_part(), ("app", "robot"));
    let v: PortValue = client
        .one("app", "robot", &What::Value("robot/speed/out".into()))
        .unwrap();
    assert_eq!(
        (v.value.as_f64(), v.unit.as_deref()),
        (Some(0.5), Some("m/s"))
    );

    let e = client
        .set::<ParamView>("app", "robot/speed/value", "1.5", "wrong")
        .unwrap_err();
    assert!(e.contains("not authorised"), "{e}");
    let e = client
        .set::<ParamView>("app", "robot/speed/value", "3", TOKEN)
        .unwrap_err();
    assert!(
        e.contains("outside the allowed range") && e.contains("keeps its value"),
        "{e}"
    );
    let p: ParamView = client
        .one("app", "robot", &What::Param("robot/speed/value".into()))
        .unwrap();
    assert_eq!(p.value, "0.5", "refused changes change nothing");
    let p: ParamView = client
        .set("app", "robot/speed/value", "1.5", TOKEN)
        .unwrap();
    assert_eq!(p.value, "1.5");
}

#[test]
fn malformed_requests_get_errors_and_the_server_serves_on() {
    let (_server, address) = serve();
    let client = Client::connect(&[address]).unwrap();
    let param = key("app", "robot", &What::Param("robot/speed/value".into()));
    for (payload, want) in [
        (&b"not json"[..], "a change is the JSON"),
        (
            &b"{\"set\": 1, \"token\": \"x\"}"[..],
            "a change is the JSON",
        ),
        (
            &b"{\"set\": \"1\", \"token\": \"x\", \"also\": 2}"[..],
            "a change is the JSON",
        ),
        (&[0xff, 0xfe, 0x00][..], "a change is the JSON"),
        (&[b' '; 70 * 1024][..], "at most"),
    ] {
        let e = error(&client, &param, Some(payload));
        assert!(e.contains(want), "{e}");
    }
    let value = key("app", "robot", &What::Value("robot/speed/out".into()));
    assert!(error(&client, &value, Some(b"{}")).contains("only parameters change"));
    // A server without a structure (a bundle's program) takes no edits.
    for what in [What::Edit, What::Model] {
        let e = error(&client, &key("app", "robot", &what), None);
        assert!(e.contains("does not take structural edits"), "{e}");
    }
    for (k, want) in [
        (
            "ferroc/app/inspect/robot/value/robot/speed/nope",
            "has no port `nope`",
        ),
        (
            "ferroc/app/inspect/robot/value/robot/ghost/out",
            "names no port or parameter",
        ),
        (
            "ferroc/app/inspect/robot/param/robot/speed/gain",
            "has no parameter `gain`",
        ),
        (
            "ferroc/app/inspect/robot/reboot",
            "not an inspection request",
        ),
        (
            "ferroc/app/inspect/robot/value/robot/*/out",
            "without wildcards",
        ),
        (
            "ferroc/app/inspect/robot/value/other/speed/out",
            "not in the part `robot`",
        ),
    ] {
        let e = error(&client, k, None);
        assert!(e.contains(want), "{k}: {e}");
    }
    // Other applications and parts are not ours to answer.
    assert!(client
        .ask("ferroc/other/inspect/robot/tree", None)
        .unwrap()
        .is_empty());
    assert!(client
        .ask("ferroc/app/inspect/station/tree", None)
        .unwrap()
        .is_empty());
    let v: PortValue = client
        .one("app", "robot", &What::Value("robot/speed/out".into()))
        .unwrap();
    assert_eq!(v.value.as_f64(), Some(0.5), "still serving");
}

#[test]
fn a_client_without_a_program_to_reach_says_so() {
    let port = ferroc_testkit::free_port();
    let e = Client::connect(&[format!("127.0.0.1:{port}")])
        .err()
        .unwrap();
    assert!(e.contains("cannot reach") && e.contains("--inspect"), "{e}");
}
