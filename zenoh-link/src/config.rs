//! The Zenoh configuration of a part: peer mode, the part's own listening endpoint,
//! every other part as an explicit endpoint, multicast scouting off (nothing leaves
//! the addresses the model names), and a short lease so that a part that dies or
//! loses its network is noticed within a second. `--zenoh-config FILE` starts from
//! the user's file instead (routers, scouting, authentication, access control); the
//! model's endpoints are added to it where the file names none.

use ferroc_runtime::link::transport::Addresses;
use std::path::Path;
use zenoh::Config;

/// How long a silent peer counts as alive (keep-alives go 4 times per lease).
pub const LEASE_MS: u64 = 500;

/// The configuration of the part `addresses.part`, from `file` if one is given.
pub fn config(addresses: &Addresses, file: Option<&Path>) -> Result<Config, String> {
    let mut config = match file {
        Some(path) => Config::from_file(path).map_err(|e| {
            format!(
                "--zenoh-config {}: not a Zenoh configuration: {e}",
                path.display()
            )
        })?,
        None => defaults()?,
    };
    // A setting the file leaves as Zenoh's default gets the model's addresses.
    let stock = Config::default();
    let empty = |config: &Config, key: &str| {
        file.is_none() || config.get_json(key).ok() == stock.get_json(key).ok()
    };
    if empty(&config, "listen/endpoints") {
        let listen = endpoint(&addresses.listen, "--listen")?;
        set(&mut config, "listen/endpoints", &format!("[\"{listen}\"]"))?;
    }
    if empty(&config, "connect/endpoints") {
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
    Ok(config)
}

/// Peer mode, no multicast scouting, fast reconnection and a short lease.
fn defaults() -> Result<Config, String> {
    let mut config = Config::default();
    set(&mut config, "mode", "\"peer\"")?;
    set(&mut config, "scouting/multicast/enabled", "false")?;
    set(
        &mut config,
        "connect/retry",
        "{ period_init_ms: 100, period_max_ms: 500, period_increase_factor: 2 }",
    )?;
    set(
        &mut config,
        "transport/link/tx/lease",
        &LEASE_MS.to_string(),
    )?;
    set(&mut config, "transport/link/tx/keep_alive", "4")?;
    Ok(config)
}

fn set(config: &mut Config, key: &str, value: &str) -> Result<(), String> {
    config
        .insert_json5(key, value)
        .map_err(|e| format!("the Zenoh setting {key} = {value} was refused: {e}"))
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
        .map_err(|e| format!("`{address}` is not an address ({option}): {e}"))
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
}
