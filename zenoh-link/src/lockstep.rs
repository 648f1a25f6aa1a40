//! Lockstep over Zenoh: the programs of an application step through the same instants
//! of model time and together print what `ferroc run --lockstep` prints.
//!
//! After each instant a part sends every part it sends to one message on
//! `ferroc/APP/lockstep/FROM/TO`: the instant and the frames of that instant for that
//! part ([`Instant`], postcard), reliably and with congestion control *block*, so
//! nothing is lost or overtaken. A part starts an instant only once every part sending
//! to it finished the previous one ("dependency-driven": parts that do not feed each
//! other do not wait for each other).
//!
//! Before its first message a part waits until the receiving part's subscriber is
//! there (the publisher's matching status), so the first instant is never lost to a
//! slow start. An instant lost later on the way (a Zenoh link that closes takes the
//! messages queued on it along) is sent again on request ([`resend`]). A part
//! it waits for whose liveliness token is withdrawn (it stopped, was killed or lost its
//! network) ends the run with an error naming it: never a hang. So does a part it only
//! sends to: its instants would go nowhere.

mod resend;

pub use resend::lose_on_the_way;

use crate::alive::{Change, Watch};
use crate::keys::Keys;
use ferroc_runtime::console;
use ferroc_runtime::link::transport::{Connection, PartLinks};
use ferroc_runtime::link::Frame;
use ferroc_terminal::engine_error;
use resend::{Inbox, Kept};
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender, TryRecvError};
use std::sync::{Arc, Mutex};
use std::time::Duration;
use zenoh::bytes::ZBytes;
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::qos::CongestionControl;
use zenoh::query::{ConsolidationMode, Query, Queryable, Reply};
use zenoh::{Session, Wait};

/// One instant of one part, for one other part.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Instant {
    /// Its number among the instants this part sent to the other (from 0).
    pub seq: u64,
    /// Model time of the instant, in nanoseconds.
    pub nanos: u64,
    /// The frames sent in it: link number and encoded value.
    pub frames: Vec<(u32, Vec<u8>)>,
}

/// What the receiving side hears, in the order it happened.
enum Event {
    /// An instant of a part; `true` when it was sent again on request.
    Instant(String, Instant, bool),
    Garbled(String, String),
    /// The part no longer keeps its instants from this number on: why.
    Unkept(String, u64, String),
    /// A part went (the watch knows which and since when): wakes the wait.
    Gone,
}

/// How long to wait in silence before saying what is awaited.
const PATIENCE: Duration = Duration::from_secs(5);

/// How long the instants a part sent before it went may still arrive: Zenoh withdraws
/// a token with priority over data, so the news that a part ended can overtake the
/// last instants it sent. A part that only sends to a part that is gone goes on for as
/// long too, so that two programs told to stop at about the same time both end cleanly.
const GRACE: Duration = Duration::from_secs(2);

/// How long a part that ends keeps its session open for the parts it sends to, to
/// take its last instants and end too (a little more than they wait for them).
const LINGER: Duration = Duration::from_secs(3);

/// How long a request for instants sent again waits for the answers.
const ASK_TIMEOUT: Duration = Duration::from_secs(2);

/// The open network of a part in lockstep.
pub(crate) struct Lockstep {
    session: Session,
    keys: Keys,
    part: String,
    to: BTreeMap<String, Outbox>,
    from: BTreeSet<String>,
    events: Mutex<Receiver<Event>>,
    /// Where the answers to requests for instants sent again go.
    answers: Mutex<Sender<Event>>,
    inboxes: Mutex<BTreeMap<String, Inbox>>,
    matched: AtomicBool,
    watch: Watch,
    _subscribers: Vec<Subscriber<()>>,
    _queryables: Vec<Queryable<()>>,
    closed: AtomicBool,
}

/// What a part keeps for one part it sends to.
struct Outbox {
    publisher: Publisher<'static>,
    key: String,
    kept: Arc<Mutex<Kept>>,
}

pub(crate) fn open(
    session: &Session,
    keys: &Keys,
    part: &str,
    links: &PartLinks,
) -> Result<Lockstep, String> {
    let (tx, rx) = mpsc::channel::<Event>();
    let from: BTreeSet<String> = links
        .receives_from()
        .into_iter()
        .map(str::to_owned)
        .collect();
    let mut subscribers = Vec::new();
    for sender in &from {
        let (tx, sender_part) = (Mutex::new(tx.clone()), sender.clone());
        let subscriber = session
            .declare_subscriber(keys.lockstep(sender, part)?)
            .callback(move |sample| {
                let bytes = sample.payload().to_bytes();
                let _ = lock(&tx).send(decode(&sender_part, &bytes, false));
            })
            .wait()
            .map_err(|e| {
                format!(
                    "cannot receive the instants of `{sender}`: {}",
                    engine_error(&e)
                )
            })?;
        subscribers.push(subscriber);
    }
    let mut to = BTreeMap::new();
    let mut queryables = Vec::new();
    for receiver in links.sends_to() {
        let key = keys.lockstep(part, receiver)?;
        let cannot =
            |e: zenoh::Error| format!("cannot send instants to `{receiver}`: {}", engine_error(&e));
        let publisher = session
            .declare_publisher(key.clone())
            .congestion_control(CongestionControl::Block)
            .wait()
            .map_err(cannot)?;
        let kept = Arc::new(Mutex::new(Kept::default()));
        let keeper = Arc::clone(&kept);
        let queryable = session
            .declare_queryable(key.clone())
            .callback(move |query| send_again(query, &keeper))
            .wait()
            .map_err(cannot)?;
        queryables.push(queryable);
        let key = key.to_string();
        let outbox = Outbox {
            publisher,
            key,
            kept,
        };
        to.insert(receiver.to_owned(), outbox);
    }
    let answers = Mutex::new(tx.clone());
    let gone = Mutex::new(tx);
    let watch = Watch::start(session, keys, part, move |change, _| {
        if let Change::Went(_) = change {
            let _ = lock(&gone).send(Event::Gone);
        }
    })?;
    Ok(Lockstep {
        session: session.clone(),
        keys: keys.clone(),
        part: part.to_owned(),
        to,
        from,
        events: Mutex::new(rx),
        answers,
        inboxes: Mutex::default(),
        matched: AtomicBool::new(false),
        watch,
        _subscribers: subscribers,
        _queryables: queryables,
        closed: AtomicBool::new(false),
    })
}

/// The event of a message of `part`: its instant, or why it does not decode.
fn decode(part: &str, bytes: &[u8], again: bool) -> Event {
    match postcard::from_bytes::<Instant>(bytes) {
        Ok(instant) => Event::Instant(part.to_owned(), instant, again),
        Err(e) => Event::Garbled(part.to_owned(), e.to_string()),
    }
}

/// Answers a request for instants sent again (`from=SEQ`): each kept one from that
/// number on, or an error if the first of them is no longer kept. The answers go from
/// a thread of their own: a callback runs on Zenoh's receiving thread, and sending
/// large instants from there (congestion control *block*) would stop this session
/// from reading while the other's reading waits for it.
fn send_again(query: Query, kept: &Mutex<Kept>) {
    let from = resend::asked_from(query.parameters().as_str());
    let answer = match from {
        Some(from) => lock(kept).from(from),
        None => Err("ask with `from=SEQ`".to_owned()),
    };
    if matches!(&answer, Ok(payloads) if payloads.is_empty()) {
        return; // nothing to send: dropping the query answers it
    }
    let _ = std::thread::Builder::new()
        .name("lockstep-again".into())
        .spawn(move || {
            let key = query.key_expr().clone();
            let _ = match answer {
                Ok(payloads) => (payloads.into_iter())
                    .try_for_each(|payload| query.reply(key.clone(), payload).wait()),
                Err(why) => query.reply_err(format!("{NOT_KEPT}{why}")).wait(),
            };
        });
}

/// How the answer that instants are no longer kept begins (Zenoh's own errors, a
/// timeout, do not).
const NOT_KEPT: &str = "not kept: ";

impl Outbox {
    /// Sends the next instant, keeping it to send again when asked.
    fn send(&self, nanos: u64, frames: Vec<(u32, Vec<u8>)>) -> zenoh::Result<()> {
        let mut kept = lock(&self.kept);
        let seq = kept.next_seq();
        let instant = Instant { seq, nanos, frames };
        let payload = ZBytes::from(postcard::to_stdvec(&instant)?);
        kept.push(payload.clone());
        drop(kept);
        if resend::to_lose(&self.key, seq) {
            return Ok(());
        }
        self.publisher.put(payload).wait()
    }
}

impl Lockstep {
    /// Asks the part `part` for its instants for this one from the number `from` on.
    fn ask(&self, part: &str, from: u64) {
        let Ok(key) = self.keys.lockstep(part, &self.part) else {
            return;
        };
        let (tx, sender) = (Mutex::new(lock(&self.answers).clone()), part.to_owned());
        let _ = (self.session.get(format!("{key}?from={from}")))
            .consolidation(ConsolidationMode::None)
            .timeout(ASK_TIMEOUT)
            .callback(move |reply: Reply| {
                let event = match reply.result() {
                    Ok(sample) => decode(&sender, &sample.payload().to_bytes(), true),
                    Err(e) => {
                        let text = e.payload().try_to_string().unwrap_or_default();
                        match text.strip_prefix(NOT_KEPT) {
                            Some(why) => Event::Unkept(sender.clone(), from, why.to_owned()),
                            None => return, // no answer in time: asked again later
                        }
                    }
                };
                let _ = lock(&tx).send(event);
            })
            .wait();
    }

    /// Takes in what arrived while waiting for the instant `nanos`.
    fn arrived(
        &self,
        inboxes: &mut BTreeMap<String, Inbox>,
        event: Event,
        nanos: u64,
    ) -> Result<(), String> {
        match event {
            Event::Instant(part, instant, again) => {
                let inbox = inboxes.entry(part).or_default();
                inbox.arrive(instant.seq, instant, again);
            }
            Event::Garbled(part, why) => {
                return Err(format!(
                    "the part `{part}` sent an instant that does not decode ({why}); are \
                     both programs built from the same model and ferroc?"
                ))
            }
            Event::Unkept(part, from, why) => {
                if inboxes.get(&part).is_none_or(|i| i.lacks(from)) {
                    return Err(format!(
                        "the instant {:.3} s of the part `{part}` was lost on the way (a \
                         Zenoh link between the two programs closed) and cannot be sent \
                         again: {why}; the run cannot stay in lockstep. help: give the \
                         parts a longer lease, e.g. \
                         `{{ transport: {{ link: {{ tx: {{ lease: 5000 }} }} }} }}` in \
                         --zenoh-config, on a loaded machine",
                        nanos as f64 / 1e9
                    ));
                }
            }
            // Only a wakeup: the wait reads the watch.
            Event::Gone => {}
        }
        Ok(())
    }

    /// Waits until every part this one sends to is listening.
    fn wait_for_receivers(&self, stop: &AtomicBool) -> Result<(), String> {
        let started = std::time::Instant::now();
        let mut told = false;
        loop {
            let missing: Vec<&str> = (self.to.iter())
                .filter(|(_, o)| {
                    !(o.publisher.matching_status().wait()).is_ok_and(|m| m.matching())
                })
                .map(|(part, _)| part.as_str())
                .collect();
            if missing.is_empty() {
                return Ok(());
            }
            if stop.load(Ordering::Relaxed) {
                return Err("interrupted".into());
            }
            if !told && started.elapsed() > PATIENCE {
                told = true;
                console::note(&format!(
                    "waiting for the part(s) {} to start",
                    names(missing.iter().copied())
                ));
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }
}

impl Connection for Lockstep {
    fn send(&self, _to_part: &str, _frame: Frame) {
        // In lockstep the driver sends everything with `end_instant`.
    }

    fn end_instant(
        &self,
        nanos: u64,
        frames: Vec<(Arc<str>, Frame)>,
        stop: &AtomicBool,
    ) -> Result<(), String> {
        if !self.matched.load(Ordering::Relaxed) {
            self.wait_for_receivers(stop)?;
            self.matched.store(true, Ordering::Relaxed);
        }
        // A part this one only sends to never makes it wait: without this, a sender
        // whose reader died would run on alone, its instants lost, as if all were well.
        for part in self.to.keys() {
            let gone = self.watch.parts.gone_since(part).map(|t| t.elapsed());
            if let Some(ago) = gone.filter(|ago| *ago >= GRACE) {
                return Err(format!(
                    "the part `{part}` is gone (its Zenoh session ended {:.1} s ago: stopped, \
                     killed or cut off); it no longer receives the instants of this part \
                     (at {:.3} s)",
                    ago.as_secs_f64(),
                    nanos as f64 / 1e9
                ));
            }
        }
        let mut by_part: BTreeMap<&str, Vec<(u32, Vec<u8>)>> = BTreeMap::new();
        for (part, frame) in frames {
            if let Some((name, _)) = self.to.get_key_value(&*part) {
                by_part
                    .entry(name)
                    .or_default()
                    .push((frame.link, frame.bytes));
            }
        }
        for (part, outbox) in &self.to {
            let frames = by_part.remove(part.as_str()).unwrap_or_default();
            outbox.send(nanos, frames).map_err(|e| {
                format!("cannot send the instant to `{part}`: {}", engine_error(&e))
            })?;
        }
        Ok(())
    }

    fn wait_instant(&self, nanos: u64, stop: &AtomicBool) -> Result<Vec<Frame>, String> {
        let events = lock(&self.events);
        let mut inboxes = lock(&self.inboxes);
        let started = std::time::Instant::now();
        for part in &self.from {
            inboxes
                .entry(part.clone())
                .or_default()
                .wait_begins(started);
        }
        let mut told = false;
        loop {
            // Everything that arrived first: what is asked for again must be missing.
            loop {
                match events.try_recv() {
                    Ok(event) => self.arrived(&mut inboxes, event, nanos)?,
                    Err(TryRecvError::Empty) => break,
                    Err(TryRecvError::Disconnected) => {
                        return Err("the network of this part was closed".into())
                    }
                }
            }
            let missing: Vec<&String> = (self.from.iter())
                .filter(|p| {
                    !(inboxes.get(*p)).is_some_and(|i| i.ready.iter().any(|i| i.nanos >= nanos))
                })
                .collect();
            if missing.is_empty() {
                break;
            }
            // Since when a part is gone is the watch's (not this call's): the news may
            // have come while an earlier call waited for an instant that still arrived.
            let lost = |p: &&&String| {
                let since = self.watch.parts.gone_since(p);
                since.is_some_and(|t| t.elapsed() >= GRACE)
            };
            if let Some(part) = missing.iter().find(lost) {
                let since = self.watch.parts.gone_since(part);
                let ago = since.map_or(0.0, |t| t.elapsed().as_secs_f64());
                return Err(format!(
                    "the part `{part}` is gone (its Zenoh session ended {ago:.1} s ago: stopped, \
                     killed or cut off) before it finished the instant {:.3} s",
                    nanos as f64 / 1e9
                ));
            }
            if stop.load(Ordering::Relaxed) {
                return Err("interrupted".into());
            }
            if !told && started.elapsed() > PATIENCE {
                told = true;
                console::note(&format!(
                    "waiting for the part(s) {} to reach the same instant",
                    names(missing.iter().map(|s| s.as_str()))
                ));
            }
            let now = std::time::Instant::now();
            for part in missing {
                if let Some(from) = inboxes.get_mut(part).and_then(|i| i.ask(now)) {
                    self.ask(part, from);
                }
            }
            match events.recv_timeout(Duration::from_millis(50)) {
                Ok(event) => self.arrived(&mut inboxes, event, nanos)?,
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => {
                    return Err("the network of this part was closed".into())
                }
            }
        }
        take(
            (inboxes.iter_mut()).map(|(part, inbox)| (part, &mut inbox.ready)),
            nanos,
        )
    }

    fn close(&self) {
        if self.closed.swap(true, Ordering::Relaxed) {
            return;
        }
        // Closing the session drops a large instant still on its way in pieces (a
        // fragmented message; the small ones after it do arrive): the reader then
        // misses instants in the middle of its last ones. So the token goes first (the
        // parts this one sends to take what is still on its way for GRACE, as they do
        // when a part ends), and the session stays open until each of them has ended
        // too (at most LINGER).
        let inboxes = lock(&self.inboxes);
        for (part, inbox) in inboxes.iter().filter(|(_, i)| i.resent > 0) {
            console::note(&format!(
                "lockstep: {} instant(s) of the part `{part}` were lost on the way (a Zenoh \
                 link closed) and sent again",
                inbox.resent
            ));
        }
        drop(inboxes);
        self.watch.withdraw();
        let until = std::time::Instant::now() + LINGER;
        while (self.to.keys()).any(|p| self.watch.parts.gone_since(p).is_none())
            && std::time::Instant::now() < until
        {
            std::thread::sleep(Duration::from_millis(5));
        }
        let _ = self.session.close().wait();
    }
}

/// The frames of the instant `nanos` (and any before it) of every part, taken from its
/// queue of instants in order. Every part steps through the same instants (the
/// application's timeline) and sends one message for each, so the instant `nanos`
/// itself must be there: a part whose next instant is a later one steps through another
/// timeline, and going on would give a different result than one process does. That is
/// an error, never silence.
fn take<'q>(
    queues: impl IntoIterator<Item = (&'q String, &'q mut VecDeque<Instant>)>,
    nanos: u64,
) -> Result<Vec<Frame>, String> {
    let mut frames = Vec::new();
    for (part, queue) in queues {
        let mut found = false;
        while queue.front().is_some_and(|i| i.nanos <= nanos) {
            let instant = queue.pop_front().expect("front exists");
            found |= instant.nanos == nanos;
            frames.extend((instant.frames.into_iter()).map(|(link, bytes)| Frame { link, bytes }));
        }
        if !found {
            return Err(format!(
                "the part `{part}` sent no instant {:.3} s but a later one: its timeline is \
                 not this part's; are both programs built from the same model and ferroc?",
                nanos as f64 / 1e9
            ));
        }
    }
    Ok(frames)
}

fn names<'a>(parts: impl Iterator<Item = &'a str>) -> String {
    parts
        .map(|p| format!("`{p}`"))
        .collect::<Vec<_>>()
        .join(", ")
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn queues(parts: &[(&str, &[u64])]) -> BTreeMap<String, VecDeque<Instant>> {
        (parts.iter())
            .map(|(part, instants)| {
                let queue = (instants.iter())
                    .map(|&nanos| Instant {
                        seq: 0,
                        nanos,
                        frames: vec![(0, nanos.to_le_bytes().to_vec())],
                    })
                    .collect();
                (part.to_string(), queue)
            })
            .collect()
    }

    #[test]
    fn the_instant_and_those_before_it_are_taken_in_order() {
        let mut q = queues(&[("a", &[10, 20, 30]), ("b", &[20])]);
        let frames = take(q.iter_mut(), 20).unwrap();
        let stamps: Vec<u8> = frames.iter().map(|f| f.bytes[0]).collect();
        assert_eq!(stamps, [10, 20, 20]);
        assert_eq!(q["a"].len(), 1, "30 stays for later");
    }

    #[test]
    fn an_instant_skipped_by_its_sender_is_an_error_naming_the_part() {
        // `a` sent 20 and then 40, not 30: another timeline.
        let mut q = queues(&[("a", &[40])]);
        let err = take(q.iter_mut(), 30_000_000).unwrap_err();
        assert!(
            err.contains("`a`") && err.contains("0.030 s") && err.contains("same model"),
            "{err}"
        );
    }
}
