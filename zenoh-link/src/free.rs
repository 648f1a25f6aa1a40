//! Running freely: each value goes out as soon as its link sends it.
//!
//! - A link this part sends has a publisher on its key (`ferroc/APP/data/…`); the link
//!   number travels as the sample's attachment (4 bytes, little-endian), since several
//!   links may leave one output. A value of at least the shared-memory threshold goes
//!   out in a buffer of the part's pool ([`crate::shm`]).
//! - For every part it receives from, one subscriber on `ferroc/APP/data/PART/**`
//!   hands the samples of the links it receives to the runtime.
//! - A service called across parts is a queryable on `ferroc/APP/service/…`; a call is
//!   a `get` with a timeout. A call to a part that is gone (no queryable) or that does
//!   not answer in time gets an error value at once, never a hang.

use crate::alive::{Change, Watch};
use crate::keys::{encoding, Keys};
#[cfg(feature = "shared-memory")]
use crate::shm::asking::Read;
use crate::shm::asking::{answering, Order, Receipt, Receipts};
use crate::shm::{Payload, Pool};
use crate::stats::{Stats, Way};
use ferroc_runtime::console;
use ferroc_runtime::link::transport::{
    call_number, send_each, Connection, Delivery, LinkKind, PartLinks, TransportUse,
};
use ferroc_runtime::link::Frame;
use ferroc_runtime::module::bytes::Holder;
use ferroc_runtime::module::lend::LentBuffer;
use ferroc_runtime::module::Encoder;
use ferroc_terminal::engine_error;
use std::borrow::Cow;
use std::collections::{BTreeMap, HashMap};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use zenoh::bytes::ZBytes;
use zenoh::key_expr::OwnedKeyExpr;
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::query::{Query, Queryable};
use zenoh::{Session, Wait};

mod calls;
mod pieces;
mod qos;
mod routes;
use calls::{queryables, Pending};
use pieces::{deliver_pieces, holders, joined, Buffers, LENT_MARK};
pub use qos::Qos;
use routes::Routes;

/// How long a call waits for its answer on the network before it fails (a client's
/// own timeout, when shorter, ends the call first).
pub const CALL_TIMEOUT: Duration = Duration::from_secs(10);

/// The open network of a part running freely.
pub(crate) struct Free {
    session: Session,
    delivery: Delivery,
    /// Per link this part sends: its publisher and what goes with each value.
    data: BTreeMap<u32, Out>,
    /// The shared-memory pool of large values (none if nothing is sent).
    pool: Option<Arc<Pool>>,
    /// How each link's values went, for `ferroc inspect`.
    stats: Stats,
    calls_out: BTreeMap<u32, OwnedKeyExpr>,
    /// Queries waiting for the service's answer, by call and request number.
    waiting: Arc<Mutex<HashMap<(u32, u64), Query>>>,
    _subscribers: Vec<Subscriber<()>>,
    /// Answers writers which of their buffers this part still holds (shm/asking.rs).
    _answering: Option<Queryable<()>>,
    /// The keys values arrived on, declared for their routes ([`routes`]).
    routes: Arc<Routes>,
    _queryables: Vec<Queryable<()>>,
    watch: Watch,
    /// Per part linked to this one: how its link is named in reports (`link robot →
    /// station`, the writer first; a part that only reads from this one is named as the
    /// reader).
    linked: BTreeMap<String, String>,
    failures: AtomicU64,
    closed: AtomicBool,
}

pub(crate) fn open(
    session: &Session,
    keys: &Keys,
    part: &str,
    links: &PartLinks,
    delivery: Delivery,
    shm: Shm,
) -> Result<Free, String> {
    if let Some(pool) = &shm.pool {
        pool.attach(session, keys.held(part)?); // who may hold what it sends (shm/reclaim.rs)
    }
    let data = publishers(session, keys, part, links)?;
    let routes = Routes::new(session);
    let receipts = Arc::new(Receipts::new(links.receiving.values().cloned()));
    let subscribers = subscribers(session, keys, links, (&delivery, &shm, &routes, &receipts))?;
    let answering = answering(session, keys.held("*")?, receipts)
        .map_err(|e| format!("cannot answer for shared memory: {}", engine_error(&e)))?;
    let waiting: Arc<Mutex<HashMap<(u32, u64), Query>>> = Arc::default();
    let queryables = queryables(session, keys, part, links, &delivery, &waiting)?;
    let mut calls_out = BTreeMap::new();
    for (id, call) in &links.calls_out {
        calls_out.insert(*id, keys.service(&call.server_part, &call.service)?);
    }
    let watch = Watch::start(session, keys, part, report(links, delivery.clone()))?;
    Ok(Free {
        session: session.clone(),
        delivery,
        data,
        pool: shm.pool,
        stats: Stats::new(links),
        calls_out,
        waiting,
        _subscribers: subscribers,
        _answering: answering,
        routes,
        _queryables: queryables,
        watch,
        linked: linked_names(part, links),
        failures: AtomicU64::new(0),
        closed: AtomicBool::new(false),
    })
}

/// The shared memory of a connection running freely.
pub(crate) struct Shm {
    /// The pool of the values it sends (none if it sends none).
    pub pool: Option<Arc<Pool>>,
    /// Counts the values that arrive in shared memory.
    pub received: Arc<AtomicU64>,
    /// Whether this part's session has shared memory on (values in lent buffers
    /// then arrive in it from writers on this computer).
    pub enabled: bool,
}

/// One link this part sends.
struct Out {
    publisher: Publisher<'static>,
    /// The link number, the sample's attachment.
    attachment: ZBytes,
    /// The attachment of a value sent in pieces around a lent buffer: the link number
    /// and [`LENT_MARK`] (made once: a value's way to its put is kept short).
    lent_attachment: ZBytes,
    /// Whether a full pool makes it wait (`true`) or drop the value.
    reliable: bool,
    /// `link robot → station (robot/x/out)`, for warnings.
    name: String,
    /// The numbers its values in shared memory are stamped with (shm/asking.rs).
    order: Order,
}

/// A publisher per link this part sends, with its attachment (the link number).
fn publishers(
    session: &Session,
    keys: &Keys,
    part: &str,
    links: &PartLinks,
) -> Result<BTreeMap<u32, Out>, String> {
    let mut data = BTreeMap::new();
    for (id, s) in &links.sending {
        let qos = Qos::of(s);
        let publisher = session
            .declare_publisher(keys.data(part, &s.topic)?)
            .encoding(encoding(&s.model_type))
            .congestion_control(qos.congestion)
            .express(qos.express)
            .wait()
            .map_err(|e| format!("cannot publish the link {id}: {}", engine_error(&e)))?;
        let lent = id.to_le_bytes().into_iter().chain([LENT_MARK]);
        let out = Out {
            publisher,
            attachment: ZBytes::from(id.to_le_bytes().to_vec()),
            lent_attachment: ZBytes::from(lent.collect::<Vec<u8>>()),
            reliable: s.reliable,
            name: format!("link {part} → {} ({})", s.to_part, s.topic),
            order: Order::default(),
        };
        data.insert(*id, out);
    }
    Ok(data)
}

/// A subscriber per part this one receives from, handing the samples of this part's
/// links to `delivery` (and their keys to `routes`).
fn subscribers(
    session: &Session,
    keys: &Keys,
    links: &PartLinks,
    (delivery, shm, routes, receipts): (&Delivery, &Shm, &Arc<Routes>, &Arc<Receipts>),
) -> Result<Vec<Subscriber<()>>, String> {
    let mut subscribers = Vec::new();
    let mut from: BTreeMap<&str, Vec<u32>> = BTreeMap::new();
    for (id, writer) in &links.receiving {
        from.entry(writer.as_str()).or_default().push(*id);
    }
    for (writer, ids) in from {
        let (delivery, writer_part) = (delivery.clone(), writer.to_owned());
        let received_shared = Arc::clone(&shm.received);
        let shm_on = shm.enabled;
        let routes = Arc::clone(routes);
        let receipts = Arc::clone(receipts);
        let subscriber = session
            .declare_subscriber(keys.data_of(writer)?)
            .callback(move |mut sample| {
                // The links the value is for (4 bytes each); those of this writer
                // that go to other parts share its keys: not ours.
                let Some(attachment) = sample.attachment_mut().map(std::mem::take) else {
                    return;
                };
                let links = attachment.to_bytes();
                let lent = links.len() % 4 == 1 && links.last() == Some(&LENT_MARK);
                let receipt = receipts.arrived(&sample); // held while read (shm/asking.rs)
                let mut links = (links.chunks_exact(4))
                    .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
                    .filter(|l| ids.contains(l))
                    .peekable();
                if lent && links.peek().is_some() {
                    // The message's buffers once, for every link of ours it carries.
                    let holders = holders(std::mem::take(sample.payload_mut()), &receipt);
                    let shared = shm_on.then_some(&*received_shared);
                    for link in links {
                        deliver_pieces(&delivery, shared, link, &holders);
                    }
                } else if !lent {
                    for link in links {
                        let payload = sample.payload();
                        deliver(&delivery, &received_shared, (link, &receipt), payload);
                    }
                }
                routes.arrived(sample.key_expr());
            })
            .wait()
            .map_err(|e| {
                format!(
                    "cannot receive from the part `{writer_part}`: {}",
                    engine_error(&e)
                )
            })?;
        subscribers.push(subscriber);
    }
    Ok(subscribers)
}

/// Hands the value `payload` of the link `link` to its receiving end.
#[cfg_attr(not(feature = "shared-memory"), allow(unused_variables))]
fn deliver(
    delivery: &Delivery,
    received_shared: &AtomicU64,
    (link, receipt): (u32, &Option<Arc<Receipt>>),
    payload: &ZBytes,
) {
    #[cfg(feature = "shared-memory")]
    if let Some(shm) = payload.as_shm() {
        // Decoded from the writer's buffer; its byte blocks (an image's pixels) stay
        // there, read in place, the buffer (and its receipt) held while the value lives.
        received_shared.fetch_add(1, Ordering::Relaxed);
        let holder: Arc<dyn Holder> = Arc::new(Read::new(shm.to_owned(), receipt));
        delivery.deliver_held(link, &holder);
        return;
    }
    match payload.to_bytes() {
        // A large value that came in pieces was joined into a new `Vec`: the value's
        // byte blocks keep ranges of it.
        Cow::Owned(joined) => {
            let holder: Arc<dyn Holder> = Arc::new(joined);
            delivery.deliver_held(link, &holder);
        }
        // Borrowed from Zenoh's buffer (a value that fits one batch): decoded straight
        // from it into the port.
        Cow::Borrowed(bytes) => delivery.deliver_bytes(link, bytes),
    }
}

/// How each part linked to this one names its link in reports (`link robot →
/// station`, the writer first).
fn linked_names(part: &str, links: &PartLinks) -> BTreeMap<String, String> {
    let mut linked = BTreeMap::new();
    for sending in links.sending.values() {
        let other = &sending.to_part;
        linked.insert(other.clone(), format!("link {part} → {other}"));
    }
    for call in links.calls_in.values() {
        linked.insert(
            call.client_part.clone(),
            format!("link {part} → {}", call.client_part),
        );
    }
    // A part this one receives from is named as the writer, even if it reads too.
    for other in links.receiving.values() {
        linked.insert(other.clone(), format!("link {other} → {part}"));
    }
    for call in links.calls_out.values() {
        let other = &call.server_part;
        linked.insert(other.clone(), format!("link {other} → {part}"));
    }
    linked
}

/// Reports parts that go and come back, naming the links they feed into this part,
/// and marks the inputs those links feed stale while their writer is gone.
fn report(
    links: &PartLinks,
    delivery: Delivery,
) -> impl Fn(&Change, Option<Duration>) + Send + Sync + 'static {
    let me = links.part.clone();
    // Per part: the links it feeds into this one, the calls this one makes to it.
    let mut feeds: BTreeMap<String, (usize, usize)> = BTreeMap::new();
    for writer in links.receiving.values() {
        feeds.entry(writer.clone()).or_default().0 += 1;
    }
    for call in links.calls_out.values() {
        feeds.entry(call.server_part.clone()).or_default().1 += 1;
    }
    move |change, back_after| match change {
        Change::Went(part) => {
            let Some((data, calls)) = feeds.get(part) else {
                return;
            };
            delivery.part_gone(part, true);
            let mut what = Vec::new();
            if *data > 0 {
                what.push(format!("{data} link(s) into {me} are stale"));
            }
            if *calls > 0 {
                what.push(format!("{calls} call(s) to it fail"));
            }
            console::note(&format!(
                "warning: link {part} → {me}: part {part} gone; {}",
                what.join(", ")
            ));
        }
        Change::Came(part) if feeds.contains_key(part) => {
            delivery.part_gone(part, false);
            if let Some(after) = back_after {
                console::note(&format!(
                    "link {part} → {me}: part {part} is back after {:.1} s; its links resume",
                    after.as_secs_f64()
                ));
            }
        }
        Change::Came(_) => {}
    }
}

impl Free {
    fn call(&self, call: u32, frame: Frame) {
        let (Some(key), Some(number)) = (self.calls_out.get(&call), call_number(&frame.bytes))
        else {
            return;
        };
        let pending = Pending {
            delivery: self.delivery.clone(),
            call,
            number,
            answered: AtomicBool::new(false),
            asked: Instant::now(),
        };
        let sent = self
            .session
            .get(key.clone())
            .payload(frame.bytes)
            .attachment(call.to_le_bytes().to_vec())
            .timeout(CALL_TIMEOUT)
            .callback(move |reply| {
                if let Ok(sample) = reply.result() {
                    if !pending.answered.swap(true, Ordering::Relaxed) {
                        let bytes = sample.payload().to_bytes().into_owned();
                        let link = LinkKind::Answer(pending.call).link();
                        pending.delivery.deliver(&Frame { link, bytes });
                    }
                }
            })
            .wait();
        if let Err(e) = sent {
            self.failed(&format!("a call could not be sent: {}", engine_error(&e)));
        }
    }

    fn answer(&self, call: u32, frame: Frame) {
        let Some(number) = call_number(&frame.bytes) else {
            return;
        };
        let Some(query) = lock(&self.waiting).remove(&(call, number)) else {
            return; // the client gave up, or its part is gone
        };
        let key = query.key_expr().clone();
        if let Err(e) = query.reply(key, frame.bytes).wait() {
            self.failed(&format!(
                "an answer could not be sent: {}",
                engine_error(&e)
            ));
        }
    }

    /// Puts a value of the data link `id` (nothing if the full pool dropped it).
    fn put(&self, id: u32, out: &Out, payload: Payload) {
        let buffers = Buffers::of(&payload);
        self.put_with(id, out, payload, out.attachment.clone(), buffers);
    }

    /// [`put`](Self::put) with the attachment `links` (the link numbers it is for),
    /// the pool buffers of `payload` at `buffers`. Only what the put needs comes
    /// before it: after a large value was filled the caches hold little but its
    /// bytes, and every line of code or data touched on the way costs a miss.
    fn put_with(&self, id: u32, out: &Out, payload: Payload, links: ZBytes, buffers: Buffers) {
        let (Payload::Shared(bytes) | Payload::Network(bytes)) = payload else {
            return; // dropped: the pool is full (warned)
        };
        // A value in shared memory is stamped with its publisher's next number.
        let stamp = !buffers.at.as_slice().is_empty();
        let (put, send) = out.order.put(&out.publisher, bytes, links, stamp);
        buffers.listed(self.pool.as_deref());
        if let Some(pool) = &self.pool {
            // The pool's ledger notes who may hold them now.
            pool.sent(buffers.at.as_slice(), send);
        }
        if let Err(e) = put {
            self.failed(&format!(
                "a value of link {id} could not be sent: {}",
                engine_error(&e)
            ));
        }
    }

    fn failed(&self, what: &str) {
        if self.failures.fetch_add(1, Ordering::Relaxed) == 0
            && !self.closed.load(Ordering::Relaxed)
        {
            console::note(&format!("warning: {what} (further failures are counted)"));
        }
    }
}

impl Connection for Free {
    fn send(&self, _to_part: &str, frame: Frame) {
        match LinkKind::of(frame.link) {
            LinkKind::Data(id) => {
                if let Some(out) = self.data.get(&id) {
                    let payload = match &self.pool {
                        Some(pool) => pool.payload(frame.bytes, out.reliable, &out.name),
                        None => Payload::Network(frame.bytes.into()),
                    };
                    let way = Way::of(&payload);
                    self.put(id, out, payload);
                    self.stats.count([id], way);
                }
            }
            LinkKind::Request(call) => self.call(call, frame),
            LinkKind::Answer(call) => self.answer(call, frame),
        }
    }

    fn send_encoded(
        &self,
        targets: &[(u32, Arc<str>)],
        encoder: &Encoder<'_>,
    ) -> Result<(), String> {
        // The links of one output share its key: one message for all of them, its
        // attachment naming each link (4 bytes each).
        let first = targets.first().and_then(|(link, _)| self.data.get(link));
        let all_data = || targets[1..].iter().all(|(l, _)| self.data.contains_key(l));
        let Some(out) = first.filter(|_| all_data()) else {
            return send_each(self, targets, encoder);
        };
        let pieces = encoder.pieces()?;
        let lent = pieces.is_some();
        let (payload, buffers) = match (&self.pool, pieces) {
            // Bytes an output lent from the pool go as they are (no copy).
            (_, Some(pieces)) => {
                let (message, buffers) = joined(pieces);
                (Payload::Shared(message), buffers)
            }
            (Some(pool), None) => {
                let payload = pool.payload_encoded(encoder, out.reliable, &out.name)?;
                let buffers = Buffers::of(&payload);
                (payload, buffers)
            }
            (None, None) => {
                let payload = Payload::Network(encoder.to_vec()?.into());
                (payload, Buffers::default())
            }
        };
        let attachment = match (targets, lent) {
            ([_], false) => out.attachment.clone(),
            ([_], true) => out.lent_attachment.clone(),
            _ => {
                let links = targets.iter().flat_map(|(l, _)| l.to_le_bytes());
                let mark = lent.then_some(LENT_MARK);
                ZBytes::from(links.chain(mark).collect::<Vec<u8>>())
            }
        };
        let way = Way::of(&payload);
        self.put_with(targets[0].0, out, payload, attachment, buffers);
        (self.stats).count(targets.iter().map(|(link, _)| *link), way);
        Ok(())
    }

    fn lend(&self, len: usize) -> Option<Box<dyn LentBuffer>> {
        self.pool.as_ref()?.lend(len)
    }

    fn end_instant(
        &self,
        _nanos: u64,
        _frames: Vec<(Arc<str>, Frame)>,
        _stop: &AtomicBool,
    ) -> Result<(), String> {
        Err("this part's network was opened to run freely, not in lockstep".into())
    }

    fn wait_instant(&self, _nanos: u64, _stop: &AtomicBool) -> Result<Vec<Frame>, String> {
        Err("this part's network was opened to run freely, not in lockstep".into())
    }

    fn status(&self) -> Vec<String> {
        let mut lines = Vec::new();
        for (part, link) in &self.linked {
            if let Some(since) = self.watch.parts.gone_since(part) {
                let secs = since.elapsed().as_secs_f64();
                lines.push(format!("{link}: part {part} gone since {secs:.1} s"));
            }
        }
        lines
    }

    fn transport(&self) -> TransportUse {
        self.stats.report(self.pool.as_deref())
    }

    fn close(&self) {
        if self.closed.swap(true, Ordering::Relaxed) {
            return;
        }
        self.watch.withdraw();
        if let Some(pool) = &self.pool {
            pool.detach();
        }
        self.routes.close();
        lock(&self.waiting).clear();
        let _ = self.session.close().wait();
    }
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}
