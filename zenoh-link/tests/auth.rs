//! Who may talk to a part: with Zenoh's user/password authentication configured
//! (`--zenoh-config`, docs/zenoh.md), a foreign session without credentials cannot
//! feed a part's inputs, while the application's parts, which have them, still can.
//! Without it, the same foreign session does feed the input: the test can tell. With
//! Zenoh's access control on top, a session with valid credentials whose user may not
//! put on a part's keys (a monitoring user) cannot feed the input either, while it may
//! still watch the values.

mod support;

use ferroc_runtime::link::transport::Addresses;
use ferroc_zenoh::Zenoh;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;
use support::*;
use zenoh::Wait;

/// A folder for this test's files.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ferroc-zenoh-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The configuration of `user`: peer mode, no scouting, its credentials, and the
/// dictionary of the application's users (so connecting sessions must have them);
/// the model's endpoints are added.
fn secure_config(dir: &Path, user: &str) -> PathBuf {
    let dictionary = users(dir);
    let file = dir.join(format!("{user}.json5"));
    let text = format!(
        r#"{{
  mode: "peer",
  scouting: {{ multicast: {{ enabled: false }} }},
  transport: {{ auth: {{ usrpwd: {{ user: "{user}", password: "secret-{user}", dictionary_file: "{}" }} }} }},
}}"#,
        dictionary.display()
    );
    std::fs::write(&file, text).unwrap();
    file
}

/// The application's users, one `user:password` a line.
fn users(dir: &Path) -> PathBuf {
    let dictionary = dir.join("users.txt");
    std::fs::write(
        &dictionary,
        "a:secret-a\nb:secret-b\nmonitor:secret-monitor\n",
    )
    .unwrap();
    dictionary
}

/// The configuration of the part `user` behind a router (docs/zenoh.md): a client of
/// the router at `router` with its credentials, listening nowhere, so that every
/// session reaches it only through the router and its access control.
fn client_config(dir: &Path, user: &str, router: &str) -> PathBuf {
    let file = dir.join(format!("{user}-client.json5"));
    let text = format!(
        r#"{{
  mode: "client",
  connect: {{ endpoints: ["tcp/{router}"] }},
  listen: {{ endpoints: [] }},
  transport: {{ auth: {{ usrpwd: {{ user: "{user}", password: "secret-{user}" }} }} }},
}}"#
    );
    std::fs::write(&file, text).unwrap();
    file
}

/// A Zenoh router on `address` that authenticates every session against the
/// application's users and applies [`ACL`].
fn router(dir: &Path, address: &str) -> zenoh::Session {
    let file = dir.join("router.json5");
    let text = format!(
        r#"{{
  mode: "router",
  listen: {{ endpoints: ["tcp/{address}"] }},
  scouting: {{ multicast: {{ enabled: false }} }},
  transport: {{ auth: {{ usrpwd: {{ dictionary_file: "{}" }} }} }},
  {ACL}
}}"#,
        users(dir).display()
    );
    std::fs::write(&file, text).unwrap();
    let config = zenoh::Config::from_file(&file).unwrap();
    zenoh::open(config).wait().unwrap()
}

/// The access control of the application `auth` with the parts `a` and `b`, as
/// docs/zenoh.md writes it for `rescue_robot`: each part may put only on its own keys,
/// the user `monitor` may only watch.
const ACL: &str = r#"access_control: {
    enabled: true,
    default_permission: "deny",
    rules: [
      { id: "a-puts", messages: ["put", "delete"], flows: ["ingress"], permission: "allow",
        key_exprs: ["ferroc/auth/data/a/**", "ferroc/auth/lockstep/a/**"] },
      { id: "b-puts", messages: ["put", "delete"], flows: ["ingress"], permission: "allow",
        key_exprs: ["ferroc/auth/data/b/**", "ferroc/auth/lockstep/b/**"] },
      { id: "parts", flows: ["ingress", "egress"], permission: "allow",
        messages: ["declare_subscriber", "declare_queryable", "query", "reply",
                   "liveliness_token", "declare_liveliness_subscriber", "liveliness_query"],
        key_exprs: ["ferroc/auth/**"] },
      { id: "to-parts", messages: ["put", "delete"], flows: ["egress"], permission: "allow",
        key_exprs: ["ferroc/auth/**"] },
      { id: "watch", flows: ["ingress", "egress"], permission: "allow",
        messages: ["declare_subscriber", "declare_liveliness_subscriber", "liveliness_query"],
        key_exprs: ["ferroc/auth/data/**", "ferroc/auth/alive/**"] },
      { id: "to-watchers", messages: ["put", "liveliness_token"], flows: ["egress"],
        permission: "allow", key_exprs: ["ferroc/auth/data/**", "ferroc/auth/alive/**"] },
    ],
    subjects: [
      { id: "a", usernames: ["a"] },
      { id: "b", usernames: ["b"] },
      { id: "monitor", usernames: ["monitor"] },
    ],
    policies: [
      { rules: ["a-puts", "parts", "to-parts"], subjects: ["a"] },
      { rules: ["b-puts", "parts", "to-parts"], subjects: ["b"] },
      { rules: ["watch", "to-watchers"], subjects: ["monitor"] },
    ],
  },"#;

fn network(part: &str, peers: &BTreeMap<String, String>, config: Option<&Path>) -> Arc<Zenoh> {
    let addresses = Addresses {
        part: part.into(),
        listen: peers[part].clone(),
        peers: peers.clone(),
    };
    Arc::new(Zenoh::new("auth", addresses, config).unwrap())
}

/// A foreign session connected to `address` with `credentials` (user, password) or
/// none, putting the value 4242 on the key of `a`'s link to `b` (link 0) for `seconds`.
fn inject(address: &str, seconds: u64, credentials: Option<(&str, &str)>) {
    let mut config = zenoh::Config::default();
    if let Some((user, password)) = credentials {
        config
            .insert_json5(
                "transport/auth/usrpwd",
                &format!("{{ user: \"{user}\", password: \"{password}\" }}"),
            )
            .unwrap();
    }
    config.insert_json5("mode", "\"peer\"").unwrap();
    config
        .insert_json5("scouting/multicast/enabled", "false")
        .unwrap();
    config
        .insert_json5("connect/endpoints", &format!("[\"tcp/{address}\"]"))
        .unwrap();
    let Ok(session) = zenoh::open(config).wait() else {
        return; // refused outright: nothing injected
    };
    let deadline = std::time::Instant::now() + Duration::from_secs(seconds);
    while std::time::Instant::now() < deadline {
        let _ = session
            .put("auth/data/a/echo/out", vec![0x92, 0x21]) // not our key: ignored
            .wait();
        let _ = session
            .put("ferroc/auth/data/a/echo/out", vec![0x92, 0x21]) // postcard 4242u32
            .attachment(0u32.to_le_bytes().to_vec())
            .wait();
        std::thread::sleep(Duration::from_millis(20));
    }
    let _ = session.close().wait();
}

fn injected(tag: u64) -> bool {
    record(tag).iter().any(|l| l.starts_with("fresh 4242 "))
}

#[test]
fn without_authentication_a_foreign_session_feeds_the_input() {
    let registry = registry();
    let peers = two_peers();
    let options = StartOptions(free(1_000_000)).with(network("b", &peers, None));
    let b = probed(&registry, "b", 401.0).start_with(options).unwrap();
    let address = peers["b"].clone();
    let injector = std::thread::spawn(move || inject(&address, 10, None));
    let fed = eventually(Duration::from_secs(20), || injected(401));
    b.stop();
    drop(b);
    let _ = injector.join();
    assert!(
        fed,
        "the foreign value reached the input: {:?}",
        record(401)
    );
}

#[test]
fn with_authentication_only_the_applications_parts_feed_the_input() {
    let registry = registry();
    let peers = two_peers();
    let dir = scratch("auth");
    let b_config = secure_config(&dir, "b");
    let options = StartOptions(free(1_000_000)).with(network("b", &peers, Some(&b_config)));
    let b = probed(&registry, "b", 402.0).start_with(options).unwrap();
    inject(&peers["b"], 3, None);
    let foreign = injected(402);
    // The application's own part, with credentials, gets through.
    let a_config = secure_config(&dir, "a");
    let options = StartOptions(free(1_000_000)).with(network("a", &peers, Some(&a_config)));
    let a = probed(&registry, "a", 402.0).start_with(options).unwrap();
    let own = eventually(Duration::from_secs(20), || {
        record(402).iter().any(|l| l.starts_with("fresh "))
    });
    a.stop();
    b.stop();
    drop((a, b));
    assert!(
        !foreign,
        "a session without credentials fed the input: {:?}",
        record(402)
    );
    assert!(own, "the part with credentials did not: {:?}", record(402));
}

#[test]
fn with_access_control_a_user_with_credentials_may_watch_but_not_feed_the_input() {
    let registry = registry();
    let peers = two_peers();
    let dir = scratch("acl");
    let address = free_port();
    let router = router(&dir, &address);
    let config = |part: &str| client_config(&dir, part, &address);
    let options = StartOptions(free(1_000_000)).with(network("b", &peers, Some(&config("b"))));
    let b = probed(&registry, "b", 403.0).start_with(options).unwrap();
    // `monitor` has valid credentials, so the router lets it in; its access control
    // refuses the monitor's puts on `a`'s keys.
    inject(&address, 3, Some(("monitor", "secret-monitor")));
    let forged = injected(403);
    // Without credentials, not even in.
    inject(&address, 1, None);
    let foreign = injected(403);
    let options = StartOptions(free(1_000_000)).with(network("a", &peers, Some(&config("a"))));
    let a = probed(&registry, "a", 403.0).start_with(options).unwrap();
    let own = eventually(Duration::from_secs(20), || {
        record(403).iter().any(|l| l.starts_with("fresh "))
    });
    // The monitor may watch: it receives `a`'s values through the router.
    let watched = watch(&address, ("monitor", "secret-monitor"));
    a.stop();
    b.stop();
    drop((a, b));
    let _ = router.close().wait();
    assert!(
        !forged && !foreign,
        "a user the access control does not let put fed the input: {:?}",
        record(403)
    );
    assert!(own, "the part allowed to put did not: {:?}", record(403));
    assert!(watched, "the monitor saw none of `a`'s values");
}

/// Whether a session of `credentials` connected to `address` receives a value on
/// `ferroc/auth/data/a/**` within 20 s.
fn watch(address: &str, (user, password): (&str, &str)) -> bool {
    let mut config = zenoh::Config::default();
    config.insert_json5("mode", "\"peer\"").unwrap();
    config
        .insert_json5("scouting/multicast/enabled", "false")
        .unwrap();
    config
        .insert_json5("connect/endpoints", &format!("[\"tcp/{address}\"]"))
        .unwrap();
    config
        .insert_json5(
            "transport/auth/usrpwd",
            &format!("{{ user: \"{user}\", password: \"{password}\" }}"),
        )
        .unwrap();
    let Ok(session) = zenoh::open(config).wait() else {
        return false;
    };
    let Ok(subscriber) = session.declare_subscriber("ferroc/auth/data/a/**").wait() else {
        return false;
    };
    let got = subscriber.recv_timeout(Duration::from_secs(20));
    let _ = session.close().wait();
    matches!(got, Ok(Some(_)))
}

/// `options` with a network.
struct StartOptions(ferroc_runtime::builder::StartOptions);
impl StartOptions {
    fn with(mut self, network: Arc<Zenoh>) -> ferroc_runtime::builder::StartOptions {
        self.0.network = Some(network);
        self.0
    }
}
