//! The calls between parts running freely: a queryable per service of this part that
//! others call, and the call this part makes that is on its way ([`Pending`]).

use super::{lock, CALL_TIMEOUT};
use crate::keys::Keys;
use ferroc_runtime::link::transport::{call_number, Delivery, LinkKind, PartLinks};
use ferroc_runtime::link::Frame;
use ferroc_terminal::engine_error;
use std::collections::{BTreeMap, HashMap};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;
use zenoh::query::{Query, Queryable};
use zenoh::{Session, Wait};

/// A queryable per service of this part called from others; its queries wait in
/// `waiting` for the service's answer.
pub(super) fn queryables(
    session: &Session,
    keys: &Keys,
    part: &str,
    links: &PartLinks,
    delivery: &Delivery,
    waiting: &Arc<Mutex<HashMap<(u32, u64), Query>>>,
) -> Result<Vec<Queryable<()>>, String> {
    let mut queryables = Vec::new();
    let mut services: BTreeMap<String, Vec<u32>> = BTreeMap::new();
    for (id, call) in &links.calls_in {
        let key = keys.service(part, &call.service)?;
        services.entry(key.to_string()).or_default().push(*id);
    }
    for (key, ids) in services {
        let (delivery, waiting) = (delivery.clone(), Arc::clone(waiting));
        let queryable = session
            .declare_queryable(key.clone())
            .callback(move |query| serve(query, &ids, &waiting, &delivery))
            .wait()
            .map_err(|e| format!("cannot serve `{key}`: {}", engine_error(&e)))?;
        queryables.push(queryable);
    }
    Ok(queryables)
}

/// A request for one of the calls `ids` arrived: keep the query for the answer and
/// hand the request to the stand-in client.
fn serve(
    query: Query,
    ids: &[u32],
    waiting: &Mutex<HashMap<(u32, u64), Query>>,
    delivery: &Delivery,
) {
    let call = query.attachment().and_then(|a| {
        a.to_bytes()
            .first_chunk::<4>()
            .map(|b| u32::from_le_bytes(*b))
    });
    let Some(call) = call.filter(|c| ids.contains(c)) else {
        return; // not a ferroc call of this part: no answer
    };
    let Some(bytes) = query.payload().map(|p| p.to_bytes().into_owned()) else {
        return;
    };
    let Some(number) = call_number(&bytes) else {
        return;
    };
    lock(waiting).insert((call, number), query);
    delivery.deliver(&Frame {
        link: LinkKind::Request(call).link(),
        bytes,
    });
}

/// One call on its way: answers the client with an error if the query ends unanswered.
pub(super) struct Pending {
    pub(super) delivery: Delivery,
    pub(super) call: u32,
    pub(super) number: u64,
    pub(super) answered: AtomicBool,
    pub(super) asked: Instant,
}

impl Drop for Pending {
    fn drop(&mut self) {
        if !self.answered.load(Ordering::Relaxed) {
            let timed_out = self.asked.elapsed() >= CALL_TIMEOUT;
            self.delivery.call_failed(self.call, self.number, timed_out);
        }
    }
}
