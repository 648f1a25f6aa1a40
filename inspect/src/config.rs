//! Zenoh sessions for inspection: the serving program listens on one address (the
//! loopback interface unless asked otherwise), the client connects to explicit
//! endpoints; both in peer mode with multicast scouting off, so nothing leaves the
//! addresses given.

use ferroc_terminal::engine_error;
use zenoh::Config;

/// The port `ferroc run --inspect` listens on by default (the parts of a bundle use
/// 47800 and up).
pub const DEFAULT_PORT: u16 = 47900;

/// `tcp/HOST:PORT` for `HOST:PORT` (or an endpoint already written `tcp/…`), checked.
pub fn endpoint(address: &str, option: &str) -> Result<String, String> {
    let text = match address.strip_prefix("tcp/") {
        Some(_) => address.to_owned(),
        None => format!("tcp/{address}"),
    };
    let host_port = &text["tcp/".len()..];
    let port = host_port.rsplit_once(':').map(|(_, p)| p.parse::<u16>());
    if !matches!(port, Some(Ok(_))) {
        return Err(format!(
            "{option} {address}: not an address HOST:PORT (e.g. 127.0.0.1:{DEFAULT_PORT})"
        ));
    }
    let host = host_port.rsplit_once(':').map_or("", |(h, _)| h);
    if !is_host(host) {
        return Err(format!(
            "{option} {address}: `{host}` is not a host name or IP address (e.g. 127.0.0.1:{DEFAULT_PORT}, [::1]:{DEFAULT_PORT})"
        ));
    }
    text.parse::<zenoh::config::EndPoint>()
        .map(|e| e.to_string())
        .map_err(|e| format!("{option} {address}: not an address: {}", engine_error(&e)))
}

/// A host name, an IPv4 address or a bracketed IPv6 address: what is neither would
/// only time out later, after Zenoh tried to reach it.
fn is_host(host: &str) -> bool {
    if let Some(inner) = host.strip_prefix('[') {
        return (inner.strip_suffix(']'))
            .is_some_and(|ip| ip.parse::<std::net::Ipv6Addr>().is_ok());
    }
    if host.bytes().all(|b| b.is_ascii_digit() || b == b'.') {
        return host.parse::<std::net::Ipv4Addr>().is_ok();
    }
    !host.is_empty()
        && !host.starts_with(['-', '.'])
        && host
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b == b'-' || b == b'.')
}

/// Whether `address` (`HOST:PORT` or `tcp/HOST:PORT`) is on the loopback interface.
pub fn is_local(address: &str) -> bool {
    let a = address.strip_prefix("tcp/").unwrap_or(address);
    let host = a.rsplit_once(':').map_or(a, |(h, _)| h);
    let host = host.trim_start_matches('[').trim_end_matches(']');
    host == "localhost"
        || host
            .parse::<std::net::IpAddr>()
            .is_ok_and(|ip| ip.is_loopback())
}

/// The largest message the serving session takes from the network: a request is at
/// most [`MAX_PAYLOAD`](crate::server::MAX_PAYLOAD) and a key. Zenoh reassembles a
/// message from its fragments before anyone sees it, up to 1 GiB by default; a larger
/// one is dropped here, before it costs memory.
pub const MAX_MESSAGE: usize = 256 * 1024;

/// The session of a serving program: listens on `address` only, and takes no
/// message larger than [`MAX_MESSAGE`].
pub fn server(address: &str) -> Result<Config, String> {
    let listen = endpoint(address, "--inspect")?;
    let mut c = base()?;
    set(&mut c, "listen/endpoints", &format!("[\"{listen}\"]"))?;
    set(&mut c, "connect/endpoints", "[]")?;
    set(
        &mut c,
        "transport/link/rx/max_message_size",
        &MAX_MESSAGE.to_string(),
    )?;
    Ok(c)
}

/// The session of `ferroc inspect`: connects to `addresses`, listens nowhere, and
/// fails at once when none answers.
pub fn client(addresses: &[String]) -> Result<Config, String> {
    if addresses.is_empty() {
        return Err(format!(
            "--connect: name the program's inspection address (e.g. --connect 127.0.0.1:{DEFAULT_PORT})"
        ));
    }
    let mut endpoints = Vec::new();
    for a in addresses {
        endpoints.push(format!("\"{}\"", endpoint(a, "--connect")?));
    }
    let mut c = base()?;
    set(&mut c, "listen/endpoints", "[]")?;
    set(
        &mut c,
        "connect/endpoints",
        &format!("[{}]", endpoints.join(",")),
    )?;
    set(&mut c, "connect/timeout_ms", "3000")?;
    set(&mut c, "connect/exit_on_failure", "true")?;
    Ok(c)
}

fn base() -> Result<Config, String> {
    let mut c = Config::default();
    set(&mut c, "mode", "\"peer\"")?;
    set(&mut c, "scouting/multicast/enabled", "false")?;
    set(&mut c, "scouting/gossip/enabled", "false")?;
    // Inspection's messages are small; and where the computer has no usable shared
    // memory (no /dev/shm, a read-only one) Zenoh would not open a session with it.
    set(&mut c, "transport/shared_memory/enabled", "false")?;
    Ok(c)
}

fn set(config: &mut Config, key: &str, value: &str) -> Result<(), String> {
    config.insert_json5(key, value).map_err(|e| {
        format!(
            "the Zenoh setting {key} = {value} was refused: {}",
            engine_error(&e)
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn loopback_addresses_are_local_and_others_are_not() {
        for local in [
            "127.0.0.1:1",
            "localhost:47900",
            "[::1]:5",
            "tcp/127.0.0.2:9",
        ] {
            assert!(is_local(local), "{local}");
        }
        for remote in ["0.0.0.0:47900", "192.168.1.5:1", "robot-pc:47900", "[::]:5"] {
            assert!(!is_local(remote), "{remote}");
        }
    }

    #[test]
    fn sessions_use_explicit_endpoints_without_multicast() {
        let s = server("127.0.0.1:47999").unwrap();
        assert!(s
            .get_json("listen/endpoints")
            .unwrap()
            .contains("tcp/127.0.0.1:47999"));
        assert_eq!(s.get_json("scouting/multicast/enabled").unwrap(), "false");
        assert_eq!(
            s.get_json("transport/link/rx/max_message_size").unwrap(),
            MAX_MESSAGE.to_string()
        );
        let c = client(&["127.0.0.1:47999".into()]).unwrap();
        assert!(c
            .get_json("connect/endpoints")
            .unwrap()
            .contains("tcp/127.0.0.1:47999"));
        assert_eq!(c.get_json("listen/endpoints").unwrap(), "[]");
        for config in [&s, &c] {
            let shm = config.get_json("transport/shared_memory/enabled");
            assert_eq!(shm.unwrap(), "false", "no shared memory for inspection");
        }
        assert!(client(&[]).unwrap_err().contains("--connect"));
        assert!(server("nonsense")
            .unwrap_err()
            .contains("--inspect nonsense"));
        for bad in ["256.1.1.1:80", "[::1:5", "tcp/[::1:5", ":80", "robot pc:80"] {
            let e = client(&[bad.to_string()]).unwrap_err();
            assert!(e.contains("is not a host name or IP address"), "{bad}: {e}");
        }
        for good in ["robot-pc:1", "[::1]:2", "localhost:3", "10.0.0.1:4"] {
            assert!(client(&[good.to_string()]).is_ok(), "{good}");
        }
    }
}
