//! Who may talk to a part: with Zenoh's user/password authentication configured
//! (`--zenoh-config`, docs/zenoh.md), a foreign session without credentials cannot
//! feed a part's inputs, while the application's parts, which have them, still can.
//! Without it, the same foreign session does feed the input: the test can tell.

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
/// dictionary of the application's users (so connecting sessions must have them).
fn secure_config(dir: &Path, user: &str) -> PathBuf {
    let dictionary = dir.join("users.txt");
    std::fs::write(&dictionary, "a:secret-a\nb:secret-b\n").unwrap();
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

fn network(part: &str, peers: &BTreeMap<String, String>, config: Option<&Path>) -> Arc<Zenoh> {
    let addresses = Addresses {
        part: part.into(),
        listen: peers[part].clone(),
        peers: peers.clone(),
    };
    Arc::new(Zenoh::new("auth", addresses, config).unwrap())
}

/// A session we did not give credentials, connected to `address`, putting the value
/// 4242 on the key of `a`'s link to `b` (link 0) for `seconds`.
fn inject(address: &str, seconds: u64) {
    let mut config = zenoh::Config::default();
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
    let injector = std::thread::spawn(move || inject(&address, 10));
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
    inject(&peers["b"], 3);
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

/// `options` with a network.
struct StartOptions(ferroc_runtime::builder::StartOptions);
impl StartOptions {
    fn with(mut self, network: Arc<Zenoh>) -> ferroc_runtime::builder::StartOptions {
        self.0.network = Some(network);
        self.0
    }
}
