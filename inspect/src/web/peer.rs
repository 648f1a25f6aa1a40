//! The web server's Zenoh peer: connected when first needed, and again after the
//! program went away, at most once per [`RETRY`] so a page polling an unreachable
//! program does not hammer it (or the web server's threads).
//!
//! A query is asked again when nobody answered only in the first [`SETTLING`] after
//! connecting (the program's declarations may still be on their way); later, once,
//! within the lookup limit: requests for an application that does not exist must not
//! hold the blocking threads an ordinary request needs.

use super::error::ApiError;
use crate::client::{Answer, Client};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// The shortest time between two connection attempts.
const RETRY: Duration = Duration::from_secs(2);

/// How long after connecting a query nobody answered is asked again.
const SETTLING: Duration = Duration::from_secs(3);

/// A lazily connected [`Client`]; every method blocks (call it on a blocking thread).
pub struct Peer {
    addresses: Vec<String>,
    /// How long one query waits for answers.
    lookup: Duration,
    state: Mutex<Connection>,
}

#[derive(Default)]
struct Connection {
    /// The client and when it connected.
    client: Option<(Arc<Client>, Instant)>,
    /// The latest failed attempt and why it failed.
    failed: Option<(Instant, String)>,
}

impl Peer {
    /// A peer that will connect to `addresses` (`HOST:PORT`); a query waits at most
    /// `lookup` for its answers.
    pub fn new(addresses: Vec<String>, lookup: Duration) -> Peer {
        Peer {
            addresses,
            lookup,
            state: Mutex::new(Connection::default()),
        }
    }

    /// The connected client (and when it connected), connecting first if needed.
    fn client(&self) -> Result<(Arc<Client>, Instant), ApiError> {
        let mut c = self.state.lock().unwrap_or_else(|p| p.into_inner());
        if let Some(client) = &c.client {
            return Ok(client.clone());
        }
        if let Some((at, why)) = &c.failed {
            if at.elapsed() < RETRY {
                return Err(ApiError::unreachable(why.clone()));
            }
        }
        match Client::connect(&self.addresses) {
            Ok(client) => {
                let client = (Arc::new(client), Instant::now());
                *c = Connection {
                    client: Some(client.clone()),
                    failed: None,
                };
                Ok(client)
            }
            Err(why) => {
                c.failed = Some((Instant::now(), why.clone()));
                Err(ApiError::unreachable(why))
            }
        }
    }

    /// Forgets the session after nobody answered: the next request connects anew.
    fn forget(&self) {
        let mut c = self.state.lock().unwrap_or_else(|p| p.into_inner());
        c.client = None;
    }

    /// Every answer to the query `key`; an error when nobody answered.
    pub fn ask(&self, key: &str, payload: Option<Vec<u8>>) -> Result<Vec<Answer>, ApiError> {
        let (client, since) = self.client()?;
        let answers = match since.elapsed() < SETTLING {
            true => client.ask_within(key, payload, self.lookup),
            false => client.ask_once(key, payload, self.lookup),
        }
        .map_err(ApiError::bad_request)?;
        if answers.is_empty() {
            self.forget();
            return Err(ApiError::unreachable(format!(
                "no program answered `{key}` on {}: is it running with --inspect there, and is the application's name right?",
                self.addresses.join(", ")
            )));
        }
        Ok(answers)
    }

    /// The first answer's JSON, or the program's error (it refused the request).
    pub fn one(&self, key: &str, payload: Option<Vec<u8>>) -> Result<serde_json::Value, ApiError> {
        let answer = self.ask(key, payload)?.into_iter().next();
        match answer.map(|a| a.result) {
            Some(Ok(json)) => Ok(json),
            Some(Err(refused)) => Err(ApiError::refused(refused)),
            None => Err(ApiError::unreachable(format!(
                "no program answered `{key}`"
            ))),
        }
    }
}
