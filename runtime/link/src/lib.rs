//! Links: connections between parts.
//!
//! A part is one program, possibly on another computer, so a connection from one part
//! to another cannot share a port. Its sending end is a step right after the writer
//! (like a converter) that encodes each new value of the reader's type
//! ([`Codec`](ferroc_module::Codec)) into a [`Frame`], paced by the connection's
//! `sharing=`; its receiving end publishes decoded values into the reader's input
//! through an ordinary port connection, so queues and wakeups work as for any input.
//!
//! The [`Hub`] routes frames. A link whose receiving end is in this process is
//! delivered here: at once when running freely (`ferroc run` runs every part in one
//! process), or at the next instant of model time in lockstep. Any other link goes to
//! its part over the [`Network`](transport::Network) given at start.
//!
//! A link's receiving end notes how fresh its values are in `ferroc_ports::fresh`, which
//! the inputs it feeds read. This crate depends on `ferroc-ports` and `ferroc-module`.

#![forbid(unsafe_code)]
#![warn(missing_docs)]

/// `eprintln!` that does not panic when standard error is closed or full (see
/// `ferroc_ports::console::stderr_line`); it shadows std's in this whole crate.
#[allow(unused_macros)] // nothing prints with it today; kept so that nothing uses std's
macro_rules! eprintln {
    ($($arg:tt)*) => {
        ferroc_ports::console::stderr_line(format_args!($($arg)*))
    };
}

#[doc(hidden)]
pub mod calls;
pub mod ros2;
pub mod ros2_wire;
pub mod transport;

use ferroc_module::bytes::Holder;
use ferroc_module::{Codec, DynOut, Encoder, Timestamp};
use ferroc_ports::fresh;
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::Duration;

/// How often a link sends: the connection's `sharing=`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sharing {
    /// Every new value, but at most one per `min_interval`; a value published within
    /// the interval is sent once it has passed (`sharing="on-change"`, the default).
    OnChange {
        /// `min-interval=` (zero: no limit).
        min_interval: Duration,
    },
    /// The latest value every `period` (`sharing="periodic"`).
    Periodic(Duration),
}

impl Default for Sharing {
    fn default() -> Self {
        Sharing::OnChange {
            min_interval: Duration::ZERO,
        }
    }
}

/// One connection between parts, as both of its ends are built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinkSpec<'a> {
    /// Its number, the same in every part (the model's connection order).
    pub id: u32,
    /// The part of the writer.
    pub from_part: &'a str,
    /// The part of the reader.
    pub to_part: &'a str,
    /// The value type on the link: the reader's model type (`rescue.VictimList`).
    pub model_type: &'a str,
    /// When values are sent.
    pub sharing: Sharing,
    /// No value may be dropped on the way (`reliability="reliable"`, or a reader
    /// queueing with `on-full="block"`); else a congested network may drop values.
    pub reliable: bool,
    /// `deadline=`: the longest silence the reader accepts. A longer gap between
    /// values is reported, and the reader's input is stale while it lasts.
    pub deadline: Option<Duration>,
}

/// One service call between parts (`<connect from="…/client" to="…/service"/>` across
/// parts), as both of its ends are built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CallSpec<'a> {
    /// Its number, the same in every part (the model's call order).
    pub id: u32,
    /// The part of the client.
    pub client_part: &'a str,
    /// The part of the service.
    pub server_part: &'a str,
    /// The service's module path and name (`station/ops/scale/scale`), which names
    /// the call on the network.
    pub service: &'a str,
}

/// One encoded value on its way.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Frame {
    /// The link it travels on.
    pub link: u32,
    /// The value, encoded.
    pub bytes: Vec<u8>,
}

/// Decides when a link's sending end sends, from the model time of each writer cycle.
#[derive(Debug)]
#[doc(hidden)]
pub struct Pace {
    sharing: Sharing,
    last_sent: Option<Timestamp>,
    waiting: bool,
}

impl Pace {
    #[doc(hidden)]
    pub fn new(sharing: Sharing) -> Self {
        Pace {
            sharing,
            last_sent: None,
            waiting: false,
        }
    }

    /// Whether to send now, given whether the writer published since the last cycle.
    #[doc(hidden)]
    pub fn send(&mut self, published: bool, now: Timestamp) -> bool {
        self.send_at(published, || now)
    }

    /// [`send`](Self::send), reading the time from `now` only when an interval needs
    /// it: a link that sends every value (the default) never reads the clock on its way
    /// to the network.
    #[doc(hidden)]
    pub fn send_at(&mut self, published: bool, now: impl FnOnce() -> Timestamp) -> bool {
        self.waiting |= published;
        let every = match self.sharing {
            Sharing::OnChange { min_interval } => min_interval,
            Sharing::Periodic(period) => period,
        };
        let due = self.waiting && (every.is_zero() || self.interval_passed(every, now()));
        if due {
            // A periodic link keeps sending the latest value; on-change waits for news.
            self.waiting = matches!(self.sharing, Sharing::Periodic(_));
        }
        due
    }

    /// Whether `every` passed since the last value sent; if so `now` is the last.
    fn interval_passed(&mut self, every: Duration, now: Timestamp) -> bool {
        let elapsed = |last: Timestamp| {
            u128::try_from(now.nanos.saturating_sub(last.nanos)).unwrap_or(0) >= every.as_nanos()
        };
        let passed = self.last_sent.is_none_or(elapsed);
        if passed {
            self.last_sent = Some(now);
        }
        passed
    }
}

/// A receiving end that handles its frames itself (the ends of service calls, and
/// parameters set from another part).
#[doc(hidden)]
pub trait Receive: Send + Sync {
    fn receive(&self, bytes: &[u8]) -> Result<(), String>;
}

/// The receiving ends of the links whose reader is in this process: data links
/// publishing into inputs, and ends that handle their frames themselves.
#[doc(hidden)]
pub struct Inbox {
    links: BTreeMap<u32, Receiving>,
    direct: BTreeMap<u32, Arc<dyn Receive>>,
    direct_failures: AtomicU64,
    /// Frames for links this part does not receive (reported once, then counted).
    unknown: AtomicU64,
}

#[doc(hidden)]
pub struct Receiving {
    pub(crate) out: DynOut,
    pub(crate) codec: Codec,
    /// `robot/vision/detector/victims → station/…`, for reports.
    pub(crate) describe: String,
    failures: AtomicU64,
    /// The writer's part.
    pub(crate) from_part: String,
    /// When values arrived, for the inputs it feeds.
    #[doc(hidden)]
    pub fresh: Arc<fresh::Freshness>,
}

impl Receiving {
    #[doc(hidden)]
    pub fn new(out: DynOut, codec: Codec, describe: String, from_part: &str) -> Self {
        Receiving {
            out,
            codec,
            describe,
            failures: AtomicU64::new(0),
            from_part: from_part.to_owned(),
            fresh: Arc::default(),
        }
    }

    /// The link's deadline (`deadline=`): its inputs are stale after this much silence.
    #[doc(hidden)]
    pub fn with_deadline(mut self, deadline: Option<Duration>) -> Self {
        self.fresh = Arc::new(fresh::Freshness::with_deadline(deadline));
        self
    }
}

impl Inbox {
    #[doc(hidden)]
    pub fn new(links: BTreeMap<u32, Receiving>, direct: BTreeMap<u32, Arc<dyn Receive>>) -> Self {
        Inbox {
            links,
            direct,
            direct_failures: AtomicU64::new(0),
            unknown: AtomicU64::new(0),
        }
    }

    /// The part `part` is gone (`true`) or back: the links it writes are stale.
    pub(crate) fn part_gone(&self, part: &str, gone: bool) {
        for link in self.links.values().filter(|l| l.from_part == part) {
            link.fresh.set_gone(gone);
        }
    }

    /// Whether the reader of `link` is in this process.
    pub(crate) fn has(&self, link: u32) -> bool {
        self.links.contains_key(&link) || self.direct.contains_key(&link)
    }

    /// Publishes a frame's value into its reader. A frame for an unknown link or one
    /// that does not decode is reported (the first time) and dropped.
    #[doc(hidden)]
    pub fn deliver(&self, frame: &Frame) {
        self.deliver_bytes(frame.link, &frame.bytes);
    }

    /// [`deliver`](Self::deliver) for a value the network still holds in its own
    /// buffer: no copy into a [`Frame`] on the way.
    pub(crate) fn deliver_bytes(&self, link_number: u32, bytes: &[u8]) {
        self.deliver_from(link_number, bytes, |link| {
            link.codec.decode(&link.out, bytes)
        });
    }

    /// [`deliver_bytes`](Self::deliver_bytes) from a buffer the value may keep: its
    /// [`Bytes`](ferroc_module::Bytes) fields read `holder` in place.
    pub(crate) fn deliver_held(&self, link_number: u32, holder: &Arc<dyn Holder>) {
        let bytes = (**holder).as_ref();
        self.deliver_from(link_number, bytes, |link| {
            link.codec.decode_held(&link.out, holder)
        });
    }

    pub(crate) fn deliver_parts(&self, link_number: u32, parts: &[Arc<dyn Holder>]) {
        if self.direct.contains_key(&link_number) {
            // A call, a parameter or a ROS 2 value is never lent: joined, as it came.
            let joined: Vec<u8> = parts.iter().flat_map(|p| (**p).as_ref()).copied().collect();
            return self.deliver_bytes(link_number, &joined);
        }
        self.deliver_from(link_number, &[], |link| {
            link.codec.decode_parts(&link.out, parts)
        });
    }

    /// Hands `bytes` to a direct end, or publishes the value `decode` makes of them
    /// into the reader of `link_number`.
    fn deliver_from(
        &self,
        link_number: u32,
        bytes: &[u8],
        decode: impl FnOnce(&Receiving) -> Result<(), String>,
    ) {
        if let Some(end) = self.direct.get(&link_number) {
            if let Err(why) = end.receive(bytes) {
                if self.direct_failures.fetch_add(1, Ordering::Relaxed) == 0 {
                    ferroc_ports::console::line(&format!(
                        "warning: a call, a parameter or a ROS 2 value between parts went wrong: {why}"
                    ));
                }
            }
            return;
        }
        let Some(link) = self.links.get(&link_number) else {
            // Reported once: a peer built from another model would repeat it forever.
            if self.unknown.fetch_add(1, Ordering::Relaxed) == 0 {
                ferroc_ports::console::line(&format!(
                    "warning: a peer sent a value for link {link_number}, which this part \
                     does not receive; are both programs built from the same model? (further \
                     such values are dropped silently)"
                ));
            }
            return;
        };
        // The arrival is noted before the value is published, so that a reader woken
        // by it sees its age and freshness, never those of the value before.
        let before = link.fresh.arriving(Timestamp::now());
        match decode(link) {
            Ok(()) => {
                if let Some(missed) = link.fresh.arrived_after(before) {
                    link.fresh.report_missed(&link.describe, missed);
                }
            }
            Err(why) => {
                link.fresh.not_arrived(before);
                if link.failures.fetch_add(1, Ordering::Relaxed) == 0 {
                    ferroc_ports::console::line(&format!(
                        "warning: {}: a value could not be decoded ({why}); it is dropped",
                        link.describe
                    ));
                }
            }
        }
    }
}

/// Where the sending ends put their frames; told how to route them at start.
#[derive(Default)]
#[doc(hidden)]
pub struct Hub {
    route: OnceLock<Route>,
}

#[doc(hidden)]
pub enum Route {
    /// Running freely: deliver local links at once, send the others.
    Direct {
        inbox: Arc<Inbox>,
        network: Option<Box<dyn transport::Connection>>,
    },
    /// In lockstep: collect everything; the driver delivers at the next instant.
    Collect(Mutex<Vec<(Arc<str>, Frame)>>),
}

impl Hub {
    #[doc(hidden)]
    pub fn set_route(&self, route: Route) {
        let _ = self.route.set(route);
    }

    /// Sends a frame towards the part `to_part`.
    #[doc(hidden)]
    pub fn send(&self, to_part: &Arc<str>, frame: Frame) {
        match self.route.get() {
            Some(Route::Direct { inbox, network }) => {
                if inbox.has(frame.link) {
                    inbox.deliver(&frame);
                } else if let Some(network) = network {
                    network.send(to_part, frame);
                }
            }
            Some(Route::Collect(frames)) => frames
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .push((Arc::clone(to_part), frame)),
            None => {}
        }
    }

    /// Sends the value `encoder` holds on each link of `targets` (link number, reading
    /// part): encoded once, straight into a buffer the network picks when they all leave
    /// this process ([`transport::Connection::send_encoded`]), into a `Vec` otherwise.
    #[doc(hidden)]
    pub fn send_encoded(
        &self,
        targets: &[(u32, Arc<str>)],
        encoder: &Encoder<'_>,
    ) -> Result<(), String> {
        if let Some(Route::Direct {
            inbox,
            network: Some(network),
        }) = self.route.get()
        {
            if targets.iter().all(|(link, _)| !inbox.has(*link)) {
                return network.send_encoded(targets, encoder);
            }
        }
        let bytes = encoder.to_vec()?;
        for (link, to_part) in targets {
            let bytes = bytes.clone();
            self.send(to_part, Frame { link: *link, bytes });
        }
        Ok(())
    }

    /// A buffer of `len` bytes for an output whose values go on the links `targets`,
    /// lent by the network when they all leave this process
    /// ([`transport::Connection::lend`]); `None` otherwise.
    #[doc(hidden)]
    pub fn lend(
        &self,
        targets: &[(u32, Arc<str>)],
        len: usize,
    ) -> Option<Box<dyn ferroc_module::lend::LentBuffer>> {
        match self.route.get() {
            Some(Route::Direct {
                inbox,
                network: Some(network),
            }) if targets.iter().all(|(link, _)| !inbox.has(*link)) => network.lend(len),
            _ => None,
        }
    }

    /// What the network reports now ([`transport::Connection::status`]).
    #[doc(hidden)]
    pub fn status(&self) -> Vec<String> {
        match self.route.get() {
            Some(Route::Direct {
                network: Some(network),
                ..
            }) => network.status(),
            _ => Vec::new(),
        }
    }

    /// How the values sent so far travelled ([`transport::Connection::transport`]);
    /// empty without a network and in lockstep.
    #[doc(hidden)]
    pub fn transport(&self) -> transport::TransportUse {
        match self.route.get() {
            Some(Route::Direct {
                network: Some(network),
                ..
            }) => network.transport(),
            _ => transport::TransportUse::default(),
        }
    }

    /// Closes the network (after the containers stopped).
    #[doc(hidden)]
    pub fn close(&self) {
        if let Some(Route::Direct {
            network: Some(network),
            ..
        }) = self.route.get()
        {
            network.close();
        }
    }

    /// The frames for parts this process does not hold, once `inbox` took its own.
    #[doc(hidden)]
    pub fn split_local(
        frames: Vec<(Arc<str>, Frame)>,
        inbox: &Inbox,
    ) -> (Vec<Frame>, Vec<(Arc<str>, Frame)>) {
        let (local, remote): (Vec<_>, Vec<_>) =
            frames.into_iter().partition(|(_, f)| inbox.has(f.link));
        (local.into_iter().map(|(_, f)| f).collect(), remote)
    }

    /// In lockstep: the frames sent since the last call.
    #[doc(hidden)]
    pub fn take_collected(&self) -> Vec<(Arc<str>, Frame)> {
        match self.route.get() {
            Some(Route::Collect(frames)) => {
                std::mem::take(&mut *frames.lock().unwrap_or_else(|e| e.into_inner()))
            }
            _ => Vec::new(),
        }
    }
}

#[cfg(test)]
mod tests;
