//! What one client of `ferroc inspect --serve` or `--foxglove` may cost: how long its
//! request head (or WebSocket upgrade) and its whole request may take, how many
//! clients are served at once, how long a lookup on the programs' network may wait.
//! A slow or idle client is dropped when its time is up, so neither many of them nor
//! one that announces a body it never sends hold a descriptor or a thread for long.
//!
//! `FERROC_INSPECT_LIMITS` (for tests, and for an operator who needs other figures)
//! sets any of them: `header_ms=200,request_ms=1000,connections=4,lookup_ms=500`.

use std::time::Duration;

/// The limits; [`Limits::default`] is what `ferroc inspect` serves with.
#[derive(Clone, Debug, PartialEq)]
pub struct Limits {
    /// A request head (or the WebSocket upgrade) must arrive within this, counted from
    /// the connection or the end of the previous request: an idle connection is closed
    /// after it.
    pub header: Duration,
    /// A whole request, body and answer included, must be done within this.
    pub request: Duration,
    /// Clients served at once; more are closed at once.
    pub connections: usize,
    /// A lookup (every query of one request) gives up after this.
    pub lookup: Duration,
}

impl Default for Limits {
    fn default() -> Limits {
        Limits {
            header: Duration::from_secs(10),
            request: Duration::from_secs(30),
            connections: 256,
            lookup: Duration::from_secs(5),
        }
    }
}

/// The environment variable that sets other limits.
pub const VARIABLE: &str = "FERROC_INSPECT_LIMITS";

impl Limits {
    /// The default limits, with what `FERROC_INSPECT_LIMITS` sets instead.
    pub fn from_env() -> Result<Limits, String> {
        match std::env::var(VARIABLE) {
            Ok(text) => Limits::parse(&text),
            Err(_) => Ok(Limits::default()),
        }
    }

    /// `header_ms=200,request_ms=1000,connections=4,lookup_ms=500` (any of them).
    pub fn parse(text: &str) -> Result<Limits, String> {
        let mut limits = Limits::default();
        for item in text.split(',').filter(|i| !i.trim().is_empty()) {
            let bad = || {
                format!(
                    "{VARIABLE}: `{item}` is not one of header_ms=N, request_ms=N, connections=N, lookup_ms=N (N > 0)"
                )
            };
            let (name, value) = item.split_once('=').ok_or_else(bad)?;
            let n: u64 = value.trim().parse().map_err(|_| bad())?;
            if n == 0 {
                return Err(bad());
            }
            match name.trim() {
                "header_ms" => limits.header = Duration::from_millis(n),
                "request_ms" => limits.request = Duration::from_millis(n),
                "lookup_ms" => limits.lookup = Duration::from_millis(n),
                "connections" => limits.connections = usize::try_from(n).map_err(|_| bad())?,
                _ => return Err(bad()),
            }
        }
        Ok(limits)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_are_set_by_name_and_nonsense_is_refused() {
        assert_eq!(Limits::parse("").unwrap(), Limits::default());
        let l = Limits::parse("header_ms=200, connections=4").unwrap();
        assert_eq!(l.header, Duration::from_millis(200));
        assert_eq!(l.connections, 4);
        assert_eq!(l.request, Limits::default().request);
        for bad in ["header=1", "connections=0", "lookup_ms=x", "request_ms"] {
            assert!(Limits::parse(bad).unwrap_err().contains(VARIABLE), "{bad}");
        }
    }
}
