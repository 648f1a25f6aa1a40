//! Asking running programs: a Zenoh peer connected to explicit endpoints, sending the
//! queries of [`request`](crate::request) and reading their JSON answers.

use crate::request::{self, EditRequest, ErrorReply, SetRequest, What};
use ferroc_terminal::engine_error;
use serde::de::DeserializeOwned;
use std::time::Duration;
use zenoh::query::ConsolidationMode;
use zenoh::{Session, Wait};

/// How long one query waits for its answers.
const QUERY_TIMEOUT: Duration = Duration::from_secs(5);

/// One answer: the key it came on and its JSON, or the server's error.
#[derive(Debug)]
pub struct Answer {
    /// `ferroc/APP/inspect/PART/…` of the answering part.
    pub key: String,
    /// The answer, or the error the server gave.
    pub result: Result<serde_json::Value, String>,
}

impl Answer {
    /// The application and part the answer's key names.
    pub fn app_part(&self) -> (&str, &str) {
        let mut c = self.key.split('/');
        let (_, app, _, part) = (c.next(), c.next(), c.next(), c.next());
        (app.unwrap_or(""), part.unwrap_or(""))
    }

    /// The answer as `T`, or the server's error, or why it is not a `T`.
    pub fn parse<T: DeserializeOwned>(&self) -> Result<T, String> {
        let json = self.result.as_ref().map_err(Clone::clone)?;
        serde_json::from_value(json.clone())
            .map_err(|e| format!("`{}` answered something unexpected: {e}", self.key))
    }
}

/// A session to the programs of one or more applications.
pub struct Client {
    session: Session,
}

impl Client {
    /// Connects to `addresses` (`HOST:PORT`); an error if none can be reached.
    pub fn connect(addresses: &[String]) -> Result<Client, String> {
        let config = crate::config::client(addresses)?;
        let session = zenoh::open(config).wait().map_err(|e| {
            let shown = addresses.join(", ");
            format!(
                "cannot reach {shown}: {}\n  help: is the program running with --inspect {shown}? \
                 (`ferroc run MODEL --inspect` serves on 127.0.0.1:{}; --connect names another address)",
                engine_error(&e),
                crate::config::DEFAULT_PORT
            )
        })?;
        Ok(Client { session })
    }

    /// Sends the query `key` (with `payload`) and collects every answer. Declarations
    /// of a program just connected to may still be on their way: a query nobody
    /// answered is asked again a few times.
    pub fn ask(&self, key: &str, payload: Option<Vec<u8>>) -> Result<Vec<Answer>, String> {
        self.ask_within(key, payload, QUERY_TIMEOUT)
    }

    /// [`ask`](Self::ask), each attempt waiting up to `timeout` for answers.
    pub fn ask_within(
        &self,
        key: &str,
        payload: Option<Vec<u8>>,
        timeout: Duration,
    ) -> Result<Vec<Answer>, String> {
        self.ask_attempts(key, payload, timeout, 5)
    }

    /// [`ask`](Self::ask) without asking again: for a server answering many requests,
    /// where a query nobody answers (an application that does not exist) must not
    /// hold a thread for the retries.
    pub fn ask_once(
        &self,
        key: &str,
        payload: Option<Vec<u8>>,
        timeout: Duration,
    ) -> Result<Vec<Answer>, String> {
        self.ask_attempts(key, payload, timeout, 1)
    }

    fn ask_attempts(
        &self,
        key: &str,
        payload: Option<Vec<u8>>,
        timeout: Duration,
        attempts: u32,
    ) -> Result<Vec<Answer>, String> {
        for attempt in 0..attempts {
            if attempt > 0 {
                std::thread::sleep(Duration::from_millis(200));
            }
            let mut get = self
                .session
                .get(key)
                .consolidation(ConsolidationMode::None)
                .timeout(timeout);
            if let Some(p) = &payload {
                get = get.payload(p.clone());
            }
            let replies = get.wait().map_err(|e| {
                format!("the query `{key}` could not be sent: {}", engine_error(&e))
            })?;
            let mut answers = Vec::new();
            while let Ok(reply) = replies.recv() {
                answers.push(read(key, &reply));
            }
            if !answers.is_empty() {
                answers.sort_by(|a, b| a.key.cmp(&b.key));
                return Ok(answers);
            }
        }
        Ok(Vec::new())
    }

    /// Sends every query of `keys` at once, then collects each one's answers (waiting
    /// at most `timeout` for each): for polling many keys at a rate, without retries.
    pub fn ask_all(&self, keys: &[String], timeout: Duration) -> Vec<Vec<Answer>> {
        let sent: Vec<_> = (keys.iter())
            .map(|key| {
                let get = self.session.get(key.as_str());
                let get = get.consolidation(ConsolidationMode::None).timeout(timeout);
                get.wait().ok()
            })
            .collect();
        (keys.iter().zip(sent))
            .map(|(key, replies)| {
                let mut answers = Vec::new();
                while let Some(Ok(reply)) = replies.as_ref().map(|r| r.recv()) {
                    answers.push(read(key, &reply));
                }
                answers
            })
            .collect()
    }

    /// Asks one part for `what`; an error when no program answers or it answers an
    /// error.
    pub fn one<T: DeserializeOwned>(
        &self,
        app: &str,
        part: &str,
        what: &What,
    ) -> Result<T, String> {
        let key = request::key(app, part, what);
        let answers = self.ask(&key, None)?;
        first(&key, answers)?.parse()
    }

    /// Sets the parameter `path` (`MODULE/PATH/NAME`) to `value` with `token`.
    pub fn set<T: DeserializeOwned>(
        &self,
        app: &str,
        path: &str,
        value: &str,
        token: &str,
    ) -> Result<T, String> {
        let key = request::key(app, part_of(path), &What::Param(path.to_owned()));
        let body = serde_json::to_vec(&SetRequest {
            set: value.to_owned(),
            token: token.to_owned(),
        })
        .map_err(|e| e.to_string())?;
        let answers = self.ask(&key, Some(body))?;
        first(&key, answers)?.parse()
    }
}

impl Client {
    /// Sends a structural edit (`ops`, a JSON list) with `token` to the part `part` of
    /// `app` (`*`: the program that answers). The answer says what changed; a refusal
    /// is an error carrying the compiler's diagnostics. Checking and switching the
    /// containers takes longer than a read: it may take up to [`EDIT_TIMEOUT`].
    pub fn edit(
        &self,
        app: &str,
        part: &str,
        ops: serde_json::Value,
        token: &str,
    ) -> Result<serde_json::Value, String> {
        let key = request::key(app, part, &What::Edit);
        let body = serde_json::to_vec(&EditRequest {
            token: token.to_owned(),
            ops,
        })
        .map_err(|e| e.to_string())?;
        let answers = self.ask_within(&key, Some(body), EDIT_TIMEOUT)?;
        first(&key, answers)?.parse()
    }
}

/// How long an edit waits for its answer.
pub const EDIT_TIMEOUT: Duration = Duration::from_secs(60);

/// The part a module path starts with.
pub fn part_of(path: &str) -> &str {
    path.split('/').next().unwrap_or(path)
}

fn first(key: &str, answers: Vec<Answer>) -> Result<Answer, String> {
    answers.into_iter().next().ok_or_else(|| {
        format!(
            "no program answered `{key}`: check the application and part names (--list shows them) and the address (--connect)"
        )
    })
}

/// A reply error that is not the server's (which are JSON): Zenoh's own, `Timeout`
/// when the program did not answer in time.
fn unanswered(key: &str, error: &str) -> String {
    if error.trim() == "Timeout" {
        format!("`{key}` was not answered in time: the program is busy or stopping; ask again")
    } else {
        format!("`{key}` was not answered: {}", engine_error(&error))
    }
}

fn read(key: &str, reply: &zenoh::query::Reply) -> Answer {
    match reply.result() {
        Ok(sample) => {
            let bytes = sample.payload().to_bytes();
            Answer {
                key: sample.key_expr().as_str().to_owned(),
                result: serde_json::from_slice(&bytes).map_err(|e| {
                    format!(
                        "`{}` answered something that is not JSON: {e}",
                        sample.key_expr()
                    )
                }),
            }
        }
        Err(e) => {
            let bytes = e.payload().to_bytes();
            let error = serde_json::from_slice::<ErrorReply>(&bytes)
                .map(|r| r.error)
                .unwrap_or_else(|_| unanswered(key, &String::from_utf8_lossy(&bytes)));
            Answer {
                key: key.to_owned(),
                result: Err(error),
            }
        }
    }
}
