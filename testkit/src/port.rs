//! Free TCP ports on loopback for tests that start programs which listen.
//!
//! Why not `bind(127.0.0.1:0)` and drop: the kernel takes that port from the
//! ephemeral range, the same range it gives every outgoing connection its source port
//! from. Between the drop and the program's own `listen`, any connection another test
//! opens (a Zenoh session connecting to a peer, a client) may take the port, and the
//! program fails with "address already in use" (seen in CI-like runs of
//! `zenoh-link/tests/shm.rs`). A port below the ephemeral range is never given to an
//! outgoing connection; a start that differs per process and a counter within one keep
//! tests from choosing the same port, and a bind proves it free right now.

use std::net::TcpListener;
use std::sync::atomic::{AtomicU32, Ordering};

/// The lowest port chosen (below it: well-known and registered services).
const LOWEST: u32 = 10_000;

/// Ports handed out by this process so far.
static HANDED_OUT: AtomicU32 = AtomicU32::new(0);

/// A TCP port on 127.0.0.1 that nothing listens on now and that the kernel does not
/// give to outgoing connections; falls back to a kernel-chosen port when the
/// ephemeral range leaves no room below it.
pub fn free_port() -> u16 {
    let (low, _) = ephemeral_range();
    if low <= LOWEST + 1_000 {
        return kernel_port();
    }
    let span = low - LOWEST;
    let start = std::process::id().wrapping_mul(7_919) % span;
    for _ in 0..span.min(5_000) {
        let n = HANDED_OUT.fetch_add(1, Ordering::Relaxed);
        let port = LOWEST + (start + n.wrapping_mul(13)) % span;
        let Ok(port) = u16::try_from(port) else {
            continue;
        };
        if TcpListener::bind(("127.0.0.1", port)).is_ok() {
            return port;
        }
    }
    kernel_port()
}

/// `free_port()` as `127.0.0.1:PORT`.
pub fn free_address() -> String {
    format!("127.0.0.1:{}", free_port())
}

/// The kernel's ephemeral port range (`/proc/sys/net/ipv4/ip_local_port_range`), or
/// Linux's default where it cannot be read.
fn ephemeral_range() -> (u32, u32) {
    let text = std::fs::read_to_string("/proc/sys/net/ipv4/ip_local_port_range");
    let mut words = text.as_deref().unwrap_or("").split_whitespace();
    let mut next = || words.next().and_then(|w| w.parse().ok());
    match (next(), next()) {
        (Some(low), Some(high)) => (low, high),
        _ => (32_768, 60_999),
    }
}

fn kernel_port() -> u16 {
    let listener = TcpListener::bind("127.0.0.1:0").expect("bind 127.0.0.1:0");
    listener.local_addr().expect("a bound address").port()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ports_are_below_the_ephemeral_range_distinct_and_free() {
        let (low, _) = ephemeral_range();
        let ports: Vec<u16> = (0..50).map(|_| free_port()).collect();
        let mut distinct = ports.clone();
        distinct.sort_unstable();
        distinct.dedup();
        assert_eq!(distinct.len(), ports.len(), "{ports:?}");
        for port in ports {
            if low > LOWEST + 1_000 {
                assert!(u32::from(port) >= LOWEST && u32::from(port) < low, "{port}");
            }
            TcpListener::bind(("127.0.0.1", port)).expect("the port is free");
        }
    }

    #[test]
    fn a_port_someone_listens_on_is_never_handed_out() {
        let taken = TcpListener::bind(("127.0.0.1", free_port())).unwrap();
        let taken = taken.local_addr().unwrap().port();
        assert!((0..200).all(|_| free_port() != taken));
    }
}
