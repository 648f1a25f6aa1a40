//! Liveliness: every part declares the token `ferroc/APP/alive/PART` once everything
//! it receives on is declared, and watches the tokens of the others. A part that stops,
//! is killed or loses its network loses its token (at once when its connection closes,
//! within the lease of [`config::LEASE_MS`](crate::config::LEASE_MS) when it goes
//! silent), and the parts linked to it are told.

use crate::keys::Keys;
use ferroc_terminal::engine_error;
use std::collections::{BTreeMap, BTreeSet};
use std::sync::{Arc, Mutex};
use std::time::Instant;
use zenoh::liveliness::LivelinessToken;
use zenoh::pubsub::Subscriber;
use zenoh::sample::SampleKind;
use zenoh::{Session, Wait};

/// A part coming or going.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Change {
    /// Its token appeared.
    Came(String),
    /// Its token was withdrawn.
    Went(String),
}

/// Which parts are alive, as their tokens say.
#[derive(Default)]
pub struct Parts {
    state: Mutex<State>,
}

#[derive(Default)]
struct State {
    alive: BTreeSet<String>,
    gone_since: BTreeMap<String, Instant>,
}

impl Parts {
    /// Whether the part's token is there.
    pub fn is_alive(&self, part: &str) -> bool {
        lock(&self.state).alive.contains(part)
    }

    /// Since when the part is gone, if its token was there and is withdrawn.
    pub fn gone_since(&self, part: &str) -> Option<Instant> {
        lock(&self.state).gone_since.get(part).copied()
    }

    /// Records a change; returns how long the part was gone when it comes back.
    fn apply(&self, change: &Change) -> Option<std::time::Duration> {
        let mut s = lock(&self.state);
        match change {
            Change::Came(p) => {
                s.alive.insert(p.clone());
                s.gone_since.remove(p).map(|t| t.elapsed())
            }
            Change::Went(p) => {
                s.alive.remove(p);
                s.gone_since.insert(p.clone(), Instant::now());
                None
            }
        }
    }
}

/// This part's token and its watch over the others'.
pub struct Watch {
    pub parts: Arc<Parts>,
    _subscriber: Subscriber<()>,
    token: Mutex<Option<LivelinessToken>>,
}

impl Watch {
    /// Watches the tokens of the application's parts (those already there included),
    /// calling `on_change` with each change and, for a part coming back, how long it
    /// was gone; then declares this part's own token.
    pub fn start(
        session: &Session,
        keys: &Keys,
        part: &str,
        on_change: impl Fn(&Change, Option<std::time::Duration>) + Send + Sync + 'static,
    ) -> Result<Watch, String> {
        let parts = Arc::new(Parts::default());
        let seen = Arc::clone(&parts);
        let watch_keys = keys.clone();
        let me = part.to_owned();
        let subscriber = session
            .liveliness()
            .declare_subscriber(keys.alive_all()?)
            .history(true)
            .callback(move |sample| {
                let Some(name) = watch_keys.part_of_alive(sample.key_expr().as_str()) else {
                    return;
                };
                if name == me {
                    return;
                }
                let change = match sample.kind() {
                    SampleKind::Put => Change::Came(name.to_owned()),
                    SampleKind::Delete => Change::Went(name.to_owned()),
                };
                let back_after = seen.apply(&change);
                on_change(&change, back_after);
            })
            .wait()
            .map_err(|e| {
                format!(
                    "cannot watch the other parts' liveliness: {}",
                    engine_error(&e)
                )
            })?;
        let token = session
            .liveliness()
            .declare_token(keys.alive(part)?)
            .wait()
            .map_err(|e| {
                format!(
                    "cannot declare the liveliness token of `{part}`: {}",
                    engine_error(&e)
                )
            })?;
        Ok(Watch {
            parts,
            _subscriber: subscriber,
            token: Mutex::new(Some(token)),
        })
    }

    /// Withdraws this part's token (the others see it go at once).
    pub fn withdraw(&self) {
        if let Some(token) = lock(&self.token).take() {
            let _ = token.undeclare().wait();
        }
    }
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}
