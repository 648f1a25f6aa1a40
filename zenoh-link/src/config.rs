//! The Zenoh configuration of a part: peer mode, the part's own listening endpoint,
//! the parts it is linked with as explicit endpoints (one side of each pair connects,
//! no gossip mesh: [`connect`]), multicast scouting off (nothing leaves the addresses
//! the model names), and a short lease so that a part that dies or loses its network is
//! noticed within two seconds (one that is killed at once: its connections close).
//!
//! `--zenoh-config FILE` (Zenoh's JSON5) is *merged* with these defaults: what
//! the file sets wins, every default the file does not set stays. So a file that only
//! adds authentication or access control keeps the short lease, the retry period and
//! the model's endpoints; a file that names its own endpoints, mode or scouting keeps
//! them. Whether the file sets a key is read from the file's own text, not by comparing
//! with Zenoh's defaults: a file that writes Zenoh's default value on purpose
//! (`scouting: { multicast: { enabled: true } }`) keeps it.

pub mod connect;
pub mod runtime;

use ferroc_runtime::link::transport::{Addresses, PartLinks};
use ferroc_terminal::engine_error;
use std::path::Path;
use zenoh::Config;

/// How long a silent peer counts as alive (keep-alives go 4 times per lease). 2 s: a
/// killed part is noticed at once anyway (its connections close), the lease only
/// matters for a cut network; with 500 ms a loaded machine let leases expire (and the
/// messages on the way were lost), and keep-alives every 125 ms on every connection
/// cost a consumer of `ferroc-bench b3-parts` measurable CPU (bench/README.md).
pub const LEASE_MS: u64 = 2000;

/// ferroc's settings on top of Zenoh's defaults (the table in docs/zenoh.md), each
/// kept unless a `--zenoh-config` file sets the key.
pub const DEFAULTS: &[(&str, &str)] = &[
    ("mode", "\"peer\""),
    ("scouting/multicast/enabled", "false"),
    (
        "connect/retry",
        "{ period_init_ms: 100, period_max_ms: 500, period_increase_factor: 2 }",
    ),
    ("transport/link/tx/lease", "2000"),
    ("transport/link/tx/keep_alive", "4"),
    // Shared memory between parts on one computer (shm.rs): on, from 4 KB, 64 MiB.
    ("transport/shared_memory/enabled", "true"),
    (
        "transport/shared_memory/transport_optimization/message_size_threshold",
        "4096",
    ),
    (
        "transport/shared_memory/transport_optimization/pool_size",
        "67108864",
    ),
];

/// A part's shared-memory settings from its model (`<part shared-memory="off"
/// shared-memory-threshold="16 KiB" shared-memory-pool="128 MiB">`, checked by the
/// compiler); `None` keeps ferroc's default. They replace the defaults above and give
/// way to a `--zenoh-config` file that sets the same key: the command line wins.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ModelShm {
    pub enabled: Option<bool>,
    pub threshold: Option<u64>,
    pub pool: Option<u64>,
}

impl ModelShm {
    /// The Zenoh keys and values the model sets.
    fn entries(&self) -> Vec<(&'static str, String)> {
        let mut entries = Vec::new();
        if let Some(on) = self.enabled {
            entries.push(("transport/shared_memory/enabled", on.to_string()));
        }
        if let Some(t) = self.threshold {
            entries.push((MESSAGE_SIZE_THRESHOLD, t.to_string()));
        }
        if let Some(p) = self.pool {
            entries.push((POOL_SIZE, p.to_string()));
        }
        entries
    }
}

/// Zenoh's keys of the two numbers (also in [`DEFAULTS`] and `shm.rs`).
const MESSAGE_SIZE_THRESHOLD: &str =
    "transport/shared_memory/transport_optimization/message_size_threshold";
const POOL_SIZE: &str = "transport/shared_memory/transport_optimization/pool_size";

/// The configuration of the part `addresses.part`: ferroc's defaults and the model's
/// endpoints (every other part), merged under `file` if one is given.
pub fn config(addresses: &Addresses, file: Option<&Path>) -> Result<Config, String> {
    config_with(addresses, file, ModelShm::default())
}

/// [`config`] with the model's shared-memory settings `model` over ferroc's defaults
/// (and under `file`).
pub fn config_with(
    addresses: &Addresses,
    file: Option<&Path>,
    model: ModelShm,
) -> Result<Config, String> {
    PartConfig::new(addresses, file, model).map(|c| c.config)
}

/// A part's configuration before its links are known: ferroc's defaults, the model's
/// settings and every other part as an endpoint, under `file`; and what the file sets,
/// so that [`PartConfig::for_links`] keeps it.
#[derive(Clone, Debug)]
pub struct PartConfig {
    config: Config,
    given: serde_json::Value,
}

impl PartConfig {
    /// The configuration of the part `addresses.part` ([`config_with`]).
    pub fn new(
        addresses: &Addresses,
        file: Option<&Path>,
        model: ModelShm,
    ) -> Result<PartConfig, String> {
        let (mut config, given) = match file {
            Some(path) => {
                let bad = |e: &dyn std::fmt::Display| {
                    format!(
                        "--zenoh-config {}: not a Zenoh configuration: {}",
                        path.display(),
                        engine_error(e)
                    )
                };
                let keys = keys_in(path).map_err(|e| bad(&e))?;
                (Config::from_file(path).map_err(|e| bad(&e))?, keys)
            }
            None => (Config::default(), serde_json::Value::Null),
        };
        for (key, value) in DEFAULTS {
            if !sets(&given, key) {
                set(&mut config, key, value)?;
            }
        }
        for (key, value) in model.entries() {
            if !sets(&given, key) {
                set(&mut config, key, &value)?;
            }
        }
        if !sets(&given, "listen/endpoints") {
            let listen = endpoint(&addresses.listen, "--listen")?;
            set(&mut config, "listen/endpoints", &format!("[\"{listen}\"]"))?;
        }
        if !sets(&given, "connect/endpoints") {
            let mut peers = Vec::new();
            for (part, address) in &addresses.peers {
                if *part != addresses.part {
                    let flag = format!("--peer {part}=HOST:PORT");
                    peers.push(format!("\"{}\"", endpoint(address, &flag)?));
                }
            }
            set(
                &mut config,
                "connect/endpoints",
                &format!("[{}]", peers.join(",")),
            )?;
        }
        Ok(PartConfig { config, given })
    }

    /// The configuration with every other part as an endpoint (and Zenoh's gossip).
    pub fn every_part(&self) -> &Config {
        &self.config
    }

    /// Whether the user's configuration file names the session's Zenoh id.
    pub fn names_an_id(&self) -> bool {
        self.given.get("id").is_some_and(|id| !id.is_null())
    }

    /// The configuration of the session of a part whose links to other parts are
    /// `links`: it connects only to the parts it is linked with, and only to those
    /// whose name sorts before its own ([`connect`]); a ROS 2 node's part keeps
    /// [`PartConfig::every_part`]. What the file sets stays.
    pub fn for_links(&self, addresses: &Addresses, links: &PartLinks) -> Result<Config, String> {
        let mut config = self.config.clone();
        connect::narrow(&mut config, &self.given, addresses, links)?;
        Ok(config)
    }
}

/// The settings a configuration file writes, as a tree. Only JSON5 (Zenoh's own
/// format, `.json5` or `.json`) is taken: the merge reads the file itself.
fn keys_in(path: &Path) -> Result<serde_json::Value, String> {
    if !matches!(
        path.extension().and_then(|e| e.to_str()),
        Some("json" | "json5")
    ) {
        return Err("the file's name must end in .json5 (Zenoh's JSON5 configuration)".into());
    }
    let text = std::fs::read_to_string(path).map_err(|e| e.to_string())?;
    json5::from_str(&text).map_err(|e| e.to_string())
}

/// Whether the tree `given` sets the key `key` (`transport/link/tx/lease`).
fn sets(given: &serde_json::Value, key: &str) -> bool {
    let mut at = given;
    for chunk in key.split('/') {
        match at.get(chunk) {
            Some(next) => at = next,
            None => return false,
        }
    }
    true
}

fn set(config: &mut Config, key: &str, value: &str) -> Result<(), String> {
    config.insert_json5(key, value).map_err(|e| {
        format!(
            "the Zenoh setting {key} = {value} was refused: {}",
            engine_error(&e)
        )
    })
}

/// `tcp/HOST:PORT` for `HOST:PORT`; an address already written as an endpoint
/// (`tcp/…`) stays as it is. `option` names where the address came from.
fn endpoint(address: &str, option: &str) -> Result<String, String> {
    let text = if address.contains('/') {
        address.to_owned()
    } else {
        let port = address.rsplit_once(':').map(|(_, p)| p.parse::<u16>());
        if !matches!(port, Some(Ok(_))) {
            return Err(format!(
                "`{address}` is not an address HOST:PORT ({option})"
            ));
        }
        format!("tcp/{address}")
    };
    text.parse::<zenoh::config::EndPoint>()
        .map(|e| e.to_string())
        .map_err(|e| {
            format!(
                "`{address}` is not an address ({option}): {}",
                engine_error(&e)
            )
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn addresses() -> Addresses {
        Addresses {
            part: "robot".into(),
            listen: "127.0.0.1:47800".into(),
            peers: [
                ("robot".to_string(), "robot-pc:47800".to_string()),
                ("station".to_string(), "base-pc:47801".to_string()),
            ]
            .into(),
        }
    }

    #[test]
    fn a_part_listens_on_its_address_and_connects_to_the_others_only() {
        let c = config(&addresses(), None).unwrap();
        assert_eq!(c.get_json("mode").unwrap(), "\"peer\"");
        assert_eq!(c.get_json("scouting/multicast/enabled").unwrap(), "false");
        let listen = c.get_json("listen/endpoints").unwrap();
        assert!(listen.contains("tcp/127.0.0.1:47800"), "{listen}");
        let connect = c.get_json("connect/endpoints").unwrap();
        assert!(connect.contains("tcp/base-pc:47801"), "{connect}");
        assert!(!connect.contains("robot-pc"), "not to itself: {connect}");
    }

    #[test]
    fn a_bad_address_or_file_is_a_clear_error() {
        let mut a = addresses();
        a.listen = "nonsense".into();
        let err = config(&a, None).unwrap_err();
        assert!(err.contains("--listen"), "{err}");
        let dir = std::env::temp_dir().join(format!("ferroc-zenoh-config-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("bad.json5");
        std::fs::write(&file, "{ mode: \"peer\", this is not json5 ").unwrap();
        let err = config(&addresses(), Some(&file)).unwrap_err();
        assert!(
            err.contains("--zenoh-config") && err.contains("bad.json5"),
            "{err}"
        );
        let missing = config(&addresses(), Some(&dir.join("missing.json5"))).unwrap_err();
        assert!(missing.contains("missing.json5"), "{missing}");
    }

    #[test]
    fn a_file_keeps_its_own_endpoints_and_gets_the_models_otherwise() {
        let dir = std::env::temp_dir().join(format!("ferroc-zenoh-file-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("router.json5");
        std::fs::write(
            &file,
            "{ mode: \"client\", connect: { endpoints: [\"tcp/10.0.0.1:7447\"] } }",
        )
        .unwrap();
        let c = config(&addresses(), Some(&file)).unwrap();
        assert_eq!(c.get_json("mode").unwrap(), "\"client\"");
        let connect = c.get_json("connect/endpoints").unwrap();
        assert!(
            connect.contains("10.0.0.1:7447") && !connect.contains("base-pc"),
            "{connect}"
        );
        let listen = c.get_json("listen/endpoints").unwrap();
        assert!(listen.contains("127.0.0.1:47800"), "{listen}");
    }

    #[test]
    fn a_file_is_merged_with_the_defaults_key_by_key() {
        let dir = std::env::temp_dir().join(format!("ferroc-zenoh-merge-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // Only a longer lease and scouting on: Zenoh's own default value, written on
        // purpose, must win over ferroc's `false` all the same.
        let file = dir.join("lease.json5");
        std::fs::write(
            &file,
            "{ transport: { link: { tx: { lease: 3000 } } }, scouting: { multicast: { enabled: true } } }",
        )
        .unwrap();
        let c = config(&addresses(), Some(&file)).unwrap();
        assert_eq!(c.get_json("transport/link/tx/lease").unwrap(), "3000");
        assert_eq!(c.get_json("scouting/multicast/enabled").unwrap(), "true");
        // What the file leaves out keeps ferroc's defaults.
        assert_eq!(c.get_json("mode").unwrap(), "\"peer\"");
        assert_eq!(c.get_json("transport/link/tx/keep_alive").unwrap(), "4");
        let retry = c.get_json("connect/retry").unwrap();
        assert!(retry.contains("100") && retry.contains("500"), "{retry}");
        assert!(c
            .get_json("connect/endpoints")
            .unwrap()
            .contains("base-pc:47801"));
        // Without a file, exactly ferroc's defaults.
        let plain = config(&addresses(), None).unwrap();
        assert_eq!(
            plain.get_json("transport/link/tx/lease").unwrap(),
            LEASE_MS.to_string()
        );
        assert_eq!(
            plain.get_json("scouting/multicast/enabled").unwrap(),
            "false"
        );
    }

    #[test]
    fn a_file_that_is_not_json5_is_refused_by_name() {
        let dir = std::env::temp_dir().join(format!("ferroc-zenoh-yaml-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("zenoh.yaml");
        std::fs::write(&file, "mode: peer\n").unwrap();
        let err = config(&addresses(), Some(&file)).unwrap_err();
        assert!(
            err.contains("--zenoh-config") && err.contains(".json5"),
            "{err}"
        );
    }

    #[test]
    fn the_models_shared_memory_settings_replace_the_defaults_and_a_file_wins() {
        use crate::shm::{Settings, POOL_SIZE as DEFAULT_POOL};
        let model = ModelShm {
            enabled: Some(true),
            threshold: Some(16 << 10),
            pool: Some(128 << 20),
        };
        let c = config_with(&addresses(), None, model).unwrap();
        let s = Settings::of(&c);
        assert_eq!(
            (s.enabled, s.threshold, s.pool_size),
            (true, 16 << 10, 128 << 20)
        );
        // Silent: a model that sets nothing keeps ferroc's defaults.
        let plain = Settings::of(&config_with(&addresses(), None, ModelShm::default()).unwrap());
        assert_eq!(plain, Settings::of(&config(&addresses(), None).unwrap()));
        assert_eq!((plain.threshold, plain.pool_size), (4096, DEFAULT_POOL));
        // A file that sets a key wins over the model; the keys it leaves keep the model's.
        let dir = std::env::temp_dir().join(format!("ferroc-zenoh-shm-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("shm.json5");
        std::fs::write(
            &file,
            "{ transport: { shared_memory: { enabled: false, transport_optimization: { pool_size: 8388608 } } } }",
        )
        .unwrap();
        let s = Settings::of(&config_with(&addresses(), Some(&file), model).unwrap());
        assert_eq!(
            (s.enabled, s.threshold, s.pool_size),
            (false, 16 << 10, 8 << 20)
        );
        let off = ModelShm {
            enabled: Some(false),
            ..ModelShm::default()
        };
        assert!(!Settings::of(&config_with(&addresses(), None, off).unwrap()).enabled);
    }
}
