//! Services and clients: the code must declare what the manifest says, since the
//! deadlock analysis trusts the manifest's execution and timeouts.

use super::differences;
use ferroc_runtime::builder::Registry;
use ferroc_runtime::module::{Module, ModuleType as RustType, Setup};
use ferroc_runtime::service::{ClientPort, ServicePort};
use std::time::Duration;

const MANIFEST: &str = r#"<library name="svc" version="1">
  <module-type name="Pair" rust="svc::Pair">
    <service name="square" request="i64" response="i64"/>
    <client name="ask" request="f64" response="bool" timeout="20ms"/>
  </module-type>
</library>
"#;

/// What the manifest says, in Rust.
struct Pair {
    _square: ServicePort<i64, i64>,
    _ask: ClientPort<f64, bool>,
}
impl Module for Pair {}
impl RustType for Pair {
    const NAME: &'static str = "svc.Pair";
    fn create(m: &mut Setup<'_>) -> Self {
        Pair {
            _square: m.service("square").build(),
            _ask: m.client("ask").timeout(Duration::from_millis(20)).build(),
        }
    }
}

/// Inline service, a response of another type, no timeout, one extra client.
struct Drifted {
    _square: ServicePort<i64, i64>,
    _ask: ClientPort<f64, i32>,
    _extra: ClientPort<f64, bool>,
}
impl Module for Drifted {}
impl RustType for Drifted {
    const NAME: &'static str = "svc.Pair";
    fn create(m: &mut Setup<'_>) -> Self {
        Drifted {
            _square: m.service("square").executed_by_caller(|x: i64| x * x),
            _ask: m.client("ask").build(),
            _extra: m.client("extra").build(),
        }
    }
}

fn compare<T: RustType>() -> Vec<String> {
    // One folder per test: tests run in parallel.
    let dir = std::env::temp_dir().join(format!(
        "ferroc-interface-{}-{}",
        std::process::id(),
        std::any::type_name::<T>().replace("::", "-")
    ));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("svc.lib.xml"), MANIFEST).unwrap();
    let options = crate::loader_options(std::slice::from_ref(&dir), false);
    let loaded = ferroc_compiler::load_manifests(&["svc".to_string()], &options);
    assert!(
        loaded.diagnostics.is_empty(),
        "{:?}",
        loaded
            .diagnostics
            .iter()
            .map(|d| &d.message)
            .collect::<Vec<_>>()
    );
    let (_, manifest) = loaded.libraries.module_type("svc.Pair").unwrap();
    let mut registry = Registry::new();
    registry.register::<T>();
    differences(manifest, &registry.interface("svc.Pair").unwrap())
}

#[test]
fn services_declared_as_in_the_manifest_agree() {
    assert_eq!(compare::<Pair>(), Vec::<String>::new());
}

#[test]
fn execution_response_timeout_and_extra_clients_are_differences() {
    let found = compare::<Drifted>();
    let expected = [
        "service `square`: the manifest says executes=\"server\", the code `caller`",
        "client `ask`: the manifest says response `bool`, the code `i32`",
        "client `ask`: the manifest says timeout `0.02s`, the code `none`",
        "the code declares <client name=\"extra\">, the manifest does not",
    ];
    for e in expected {
        assert!(found.iter().any(|f| f == e), "missing {e:?} in {found:#?}");
    }
    assert_eq!(found.len(), expected.len(), "{found:#?}");
}

#[test]
fn defaults_compare_by_value() {
    use super::same_default;
    assert!(same_default(Some("0.5"), Some(".5")));
    assert!(same_default(Some("200ms"), Some("0.2s")));
    assert!(same_default(Some("PT0.5S"), Some("0.5s")));
    assert!(!same_default(Some("200ms"), Some("0.3s")));
    assert!(same_default(Some("idle"), Some("idle")));
    assert!(!same_default(Some("idle"), Some("explore")));
    assert!(!same_default(Some("1s"), None));
}

/// The compiler refuses a port group the runtime would cut short (M116 above the limit):
/// both must use one number.
#[test]
fn the_compiler_bounds_port_groups_as_the_runtime_does() {
    assert_eq!(
        ferroc_compiler::syntax::vocabulary::MAX_GROUP_PORTS,
        ferroc_runtime::module::MAX_GROUP_PORTS
    );
}
