//! The keys a part's values arrive on, declared in its own session once each.
//!
//! A part subscribes to everything a writer part sends (`ferroc/APP/data/PART/**`) and
//! does not know the writers' keys in advance. Zenoh caches the route of a value only
//! for a key it holds a node of; for any other key it matches the key against every
//! subscription again for each value (`compute_data_route`: b4-large's reader spent
//! several microseconds a value there, on the way to the callback, where a bare
//! subscriber on the exact key spends none). So the first value on a key has that key
//! declared here (`Session::declare_keyexpr`: a node in this session's routing
//! tables), and the values after it take the cached route.
//!
//! The declaration cannot run in the callback, which Zenoh calls holding its routing
//! tables (a declaration writes them): a short-lived thread makes it. At most
//! [`MOST`] keys per part are learnt, so a peer sending on ever new keys costs nothing
//! more than before.

use std::collections::HashSet;
use std::sync::{Arc, Mutex, MutexGuard};
use zenoh::key_expr::{KeyExpr, OwnedKeyExpr};
use zenoh::{Session, Wait};

/// The most keys learnt per part.
pub(super) const MOST: usize = 256;

/// How many keys are compared before the set of all is asked.
const FEW: usize = 8;

/// The keys learnt so far, and the session they are declared in (none once closed).
#[derive(Default)]
pub(super) struct Routes {
    state: Mutex<State>,
}

#[derive(Default)]
struct State {
    session: Option<Session>,
    /// The first [`FEW`] keys seen, looked at before `seen`: a part's values mostly
    /// come on a few keys, and comparing a key is cheaper than hashing it (SipHash of
    /// the key was ~250 instructions a value in Zenoh's receive thread).
    first: Vec<OwnedKeyExpr>,
    seen: HashSet<OwnedKeyExpr>,
    /// Kept so that the nodes stay for as long as the session.
    declared: Vec<KeyExpr<'static>>,
}

impl Routes {
    /// Learning keys in `session`.
    pub(super) fn new(session: &Session) -> Arc<Self> {
        let routes = Routes::default();
        lock(&routes.state).session = Some(session.clone());
        Arc::new(routes)
    }

    /// A value arrived on `key`: the first time, declare it (on another thread).
    pub(super) fn arrived(self: &Arc<Self>, key: &KeyExpr<'_>) {
        let session = {
            let mut state = lock(&self.state);
            let key = key.as_keyexpr();
            if state.first.iter().any(|k| **k == *key) {
                return;
            }
            if state.seen.len() >= MOST || state.seen.contains(key) {
                return;
            }
            state.seen.insert(key.to_owned());
            if state.first.len() < FEW {
                state.first.push(key.to_owned());
            }
            match &state.session {
                Some(session) => session.clone(),
                None => return,
            }
        };
        let (routes, key) = (Arc::clone(self), key.as_keyexpr().to_owned());
        let declare = move || {
            if let Ok(declared) = session.declare_keyexpr(key).wait() {
                lock(&routes.state).declared.push(declared);
            }
        };
        // Without a thread the key is simply not learnt (the route is computed per value).
        let _ = std::thread::Builder::new()
            .name("ferroc-routes".into())
            .spawn(declare);
    }

    /// How many keys were seen and declared so far.
    #[cfg(test)]
    fn counts(&self) -> (usize, usize) {
        let state = lock(&self.state);
        (state.seen.len(), state.declared.len())
    }

    /// The session closes: let go of it (the subscriber's callback holds this).
    pub(super) fn close(&self) {
        let mut state = lock(&self.state);
        state.session = None;
        state.declared.clear();
    }
}

fn lock(m: &Mutex<State>) -> MutexGuard<'_, State> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::{Duration, Instant};

    fn session() -> Session {
        let mut c = zenoh::Config::default();
        c.insert_json5("scouting/multicast/enabled", "false")
            .unwrap();
        c.insert_json5("listen/endpoints", "[]").unwrap();
        zenoh::open(c).wait().unwrap()
    }

    /// Waits (at most 20 s, not a timing check) until `done` holds.
    fn until(mut done: impl FnMut() -> bool) -> bool {
        let deadline = Instant::now() + Duration::from_secs(20);
        while !done() {
            if Instant::now() > deadline {
                return false;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        true
    }

    #[test]
    fn the_first_value_on_a_key_has_it_declared_once_and_later_ones_nothing() {
        let s = session();
        let routes = Routes::new(&s);
        let learn = Arc::clone(&routes);
        let arrived = Arc::new(std::sync::atomic::AtomicUsize::new(0));
        let count = Arc::clone(&arrived);
        let _sub = (s.declare_subscriber("ferroc/t/data/w/**"))
            .callback(move |sample| {
                learn.arrived(sample.key_expr());
                count.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
            })
            .wait()
            .unwrap();
        s.put("ferroc/t/data/w/m/out", vec![1u8]).wait().unwrap();
        assert!(until(|| routes.counts() == (1, 1)), "{:?}", routes.counts());
        // Learnt: the same key again is neither seen anew nor declared again.
        s.put("ferroc/t/data/w/m/out", vec![2u8]).wait().unwrap();
        let two = || arrived.load(std::sync::atomic::Ordering::SeqCst) == 2;
        assert!(until(two));
        assert_eq!(routes.counts(), (1, 1));
        routes.close();
        s.close().wait().unwrap();
    }

    #[test]
    fn at_most_so_many_keys_are_learnt_and_none_once_closed() {
        let s = session();
        let routes = Routes::new(&s);
        for i in 0..MOST + 10 {
            let key = KeyExpr::try_from(format!("ferroc/t/data/w/k{i}")).unwrap();
            routes.arrived(&key);
        }
        assert_eq!(routes.counts().0, MOST);
        assert!(until(|| routes.counts().1 == MOST));
        routes.close();
        assert_eq!(routes.counts(), (MOST, 0));
        let closed = Routes::new(&s);
        closed.close();
        closed.arrived(&KeyExpr::try_from("ferroc/t/data/w/late").unwrap());
        // Seen, but with no session nothing is declared (no thread is started).
        assert_eq!(closed.counts(), (1, 0));
        s.close().wait().unwrap();
    }
}
