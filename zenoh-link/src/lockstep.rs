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
//! there (the publisher's matching status), so the first instant is never lost. A part
//! it waits for whose liveliness token is withdrawn (it stopped, was killed or lost its
//! network) ends the run with an error naming it: never a hang. So does a part it only
//! sends to: its instants would go nowhere.

use crate::alive::{Change, Watch};
use crate::keys::Keys;
use ferroc_runtime::console;
use ferroc_runtime::link::transport::{Connection, PartLinks};
use ferroc_runtime::link::Frame;
use ferroc_terminal::engine_error;
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::sync::{Arc, Mutex};
use std::time::Duration;
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::qos::CongestionControl;
use zenoh::{Session, Wait};

/// One instant of one part, for one other part.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Instant {
    /// Model time of the instant, in nanoseconds.
    pub nanos: u64,
    /// The frames sent in it: link number and encoded value.
    pub frames: Vec<(u32, Vec<u8>)>,
}

/// What the receiving side hears, in the order it happened.
enum Event {
    Instant(String, Instant),
    Garbled(String, String),
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

/// The open network of a part in lockstep.
pub(crate) struct Lockstep {
    session: Session,
    to: BTreeMap<String, Publisher<'static>>,
    from: BTreeSet<String>,
    events: Mutex<Receiver<Event>>,
    queues: Mutex<BTreeMap<String, VecDeque<Instant>>>,
    matched: AtomicBool,
    watch: Watch,
    _subscribers: Vec<Subscriber<()>>,
    closed: AtomicBool,
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
                let event = match postcard::from_bytes::<Instant>(&bytes) {
                    Ok(instant) => Event::Instant(sender_part.clone(), instant),
                    Err(e) => Event::Garbled(sender_part.clone(), e.to_string()),
                };
                let _ = lock(&tx).send(event);
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
    for receiver in links.sends_to() {
        let publisher = session
            .declare_publisher(keys.lockstep(part, receiver)?)
            .congestion_control(CongestionControl::Block)
            .wait()
            .map_err(|e| format!("cannot send instants to `{receiver}`: {}", engine_error(&e)))?;
        to.insert(receiver.to_owned(), publisher);
    }
    let gone = Mutex::new(tx);
    let watch = Watch::start(session, keys, part, move |change, _| {
        if let Change::Went(_) = change {
            let _ = lock(&gone).send(Event::Gone);
        }
    })?;
    Ok(Lockstep {
        session: session.clone(),
        to,
        from,
        events: Mutex::new(rx),
        queues: Mutex::default(),
        matched: AtomicBool::new(false),
        watch,
        _subscribers: subscribers,
        closed: AtomicBool::new(false),
    })
}

impl Lockstep {
    /// Waits until every part this one sends to is listening.
    fn wait_for_receivers(&self, stop: &AtomicBool) -> Result<(), String> {
        let started = std::time::Instant::now();
        let mut told = false;
        loop {
            let missing: Vec<&str> = (self.to.iter())
                .filter(|(_, p)| !p.matching_status().wait().is_ok_and(|m| m.matching()))
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
        for (part, publisher) in &self.to {
            let instant = Instant {
                nanos,
                frames: by_part.remove(part.as_str()).unwrap_or_default(),
            };
            let bytes = postcard::to_stdvec(&instant).map_err(|e| e.to_string())?;
            publisher.put(bytes).wait().map_err(|e| {
                format!("cannot send the instant to `{part}`: {}", engine_error(&e))
            })?;
        }
        Ok(())
    }

    fn wait_instant(&self, nanos: u64, stop: &AtomicBool) -> Result<Vec<Frame>, String> {
        let events = lock(&self.events);
        let mut queues = lock(&self.queues);
        let started = std::time::Instant::now();
        let mut told = false;
        loop {
            let missing: Vec<&String> = (self.from.iter())
                .filter(|p| {
                    !queues
                        .get(*p)
                        .is_some_and(|q| q.iter().any(|i| i.nanos >= nanos))
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
            match events.recv_timeout(Duration::from_millis(50)) {
                Ok(Event::Instant(part, instant)) => {
                    queues.entry(part).or_default().push_back(instant)
                }
                Ok(Event::Garbled(part, why)) => {
                    return Err(format!(
                        "the part `{part}` sent an instant that does not decode ({why}); are \
                         both programs built from the same model and ferroc?"
                    ))
                }
                // Only a wakeup: `lost` above reads the watch.
                Ok(Event::Gone) => {}
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => {
                    return Err("the network of this part was closed".into())
                }
            }
        }
        take(&mut queues, nanos)
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

/// The frames of the instant `nanos` (and any before it) of every part, taken from
/// `queues`. Every part steps through the same instants (the application's timeline)
/// and sends one message for each, so the instant `nanos` itself must be there: if a
/// later one came instead, messages were lost on the way (the session between the two
/// programs dropped and came back within the grace period), and going on would give a
/// different result than one process does. That is an error, never silence.
fn take(
    queues: &mut BTreeMap<String, VecDeque<Instant>>,
    nanos: u64,
) -> Result<Vec<Frame>, String> {
    let mut frames = Vec::new();
    for (part, queue) in queues.iter_mut() {
        let mut found = false;
        while queue.front().is_some_and(|i| i.nanos <= nanos) {
            let instant = queue.pop_front().expect("front exists");
            found |= instant.nanos == nanos;
            frames.extend((instant.frames.into_iter()).map(|(link, bytes)| Frame { link, bytes }));
        }
        if !found {
            return Err(format!(
                "the instant {:.3} s of the part `{part}` was lost on the way (its Zenoh \
                 session to this part dropped and came back); the run cannot stay in \
                 lockstep. help: give the parts a longer lease, e.g. \
                 `{{ transport: {{ link: {{ tx: {{ lease: 5000 }} }} }} }}` in --zenoh-config, \
                 on a loaded machine",
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
        let frames = take(&mut q, 20).unwrap();
        let stamps: Vec<u8> = frames.iter().map(|f| f.bytes[0]).collect();
        assert_eq!(stamps, [10, 20, 20]);
        assert_eq!(q["a"].len(), 1, "30 stays for later");
    }

    #[test]
    fn a_lost_instant_is_an_error_naming_the_part_and_the_lease() {
        // `a` sent 20, 30 and 40, but 30 never arrived.
        let mut q = queues(&[("a", &[40])]);
        let err = take(&mut q, 30).unwrap_err();
        assert!(
            err.contains("`a`") && err.contains("0.000 s") && err.contains("lease"),
            "{err}"
        );
    }
}
