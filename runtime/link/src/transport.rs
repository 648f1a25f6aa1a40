//! The network between parts, as the runtime sees it.
//!
//! The runtime itself opens no sockets: links whose other end is in another program
//! go through a [`Network`] given in `StartOptions` (`ferroc_app::builder`).
//! ferroc's network is Eclipse Zenoh (the `ferroc-zenoh` crate), kept out of this crate
//! so that the runtime depends on neither Zenoh nor an async runtime. A network learns
//! at start which links leave and enter this part ([`PartLinks`]), hands what arrives
//! to a [`Delivery`], and carries frames: at once when running freely, one batch per
//! instant of model time in lockstep.

use super::calls;
use super::{Frame, Inbox, Sharing};
use ferroc_module::bytes::Holder;
use ferroc_module::lend::LentBuffer;
use ferroc_module::Encoder;
use std::collections::BTreeMap;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// Where this part is and where the other parts are (from the model and the command
/// line of a generated program).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Addresses {
    /// This part's name.
    pub part: String,
    /// Where this part listens for the others (`0.0.0.0:47801`).
    pub listen: String,
    /// Every part's address (`station` → `base-pc:47802`), this one's included.
    pub peers: BTreeMap<String, String>,
}

/// A data or parameter link this part sends to another part.
#[derive(Clone, Debug, PartialEq)]
pub struct Sending {
    /// The reading part.
    pub to_part: String,
    /// The writer's module path and output port (`robot/vision/detector/victims`).
    pub topic: String,
    /// The value type (`rescue.VictimList`).
    pub model_type: String,
    /// When values are sent (paced by the runtime; a network may use it for its QoS).
    pub sharing: Sharing,
    /// No value may be dropped on the way (see [`LinkSpec::reliable`](super::LinkSpec)).
    pub reliable: bool,
}

/// A service call between this part and another.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RemoteCall {
    /// The client's part.
    pub client_part: String,
    /// The service's part.
    pub server_part: String,
    /// The service's module path and name (`station/ops/scale/scale`).
    pub service: String,
}

/// What leaves and enters this part over the network.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PartLinks {
    /// This part's name.
    pub part: String,
    /// Links this part sends to other parts, by link number.
    pub sending: BTreeMap<u32, Sending>,
    /// Links this part receives from other parts: link number → the writer's part.
    pub receiving: BTreeMap<u32, String>,
    /// Calls this part's clients make to services in other parts, by call number.
    pub calls_out: BTreeMap<u32, RemoteCall>,
    /// Calls from other parts' clients to this part's services, by call number.
    pub calls_in: BTreeMap<u32, RemoteCall>,
    /// The ROS 2 nodes of the parts built here, with their topics
    /// ([`ros2`](super::ros2)): a network that speaks ROS 2 declares them.
    pub ros2: Vec<super::ros2::Ros2Node>,
}

impl PartLinks {
    /// Whether anything crosses to or from another part.
    pub fn is_empty(&self) -> bool {
        self.sending.is_empty()
            && self.receiving.is_empty()
            && self.calls_out.is_empty()
            && self.calls_in.is_empty()
            && self.ros2.is_empty()
    }

    /// Whether anything crosses to or from another part (ROS 2 nodes aside).
    pub fn has_parts(&self) -> bool {
        !(self.sending.is_empty()
            && self.receiving.is_empty()
            && self.calls_out.is_empty()
            && self.calls_in.is_empty())
    }

    /// The parts this one sends frames to (data, requests, answers).
    pub fn sends_to(&self) -> std::collections::BTreeSet<&str> {
        let data = self.sending.values().map(|s| s.to_part.as_str());
        let requests = self.calls_out.values().map(|c| c.server_part.as_str());
        let answers = self.calls_in.values().map(|c| c.client_part.as_str());
        data.chain(requests).chain(answers).collect()
    }

    /// The parts this one receives frames from.
    pub fn receives_from(&self) -> std::collections::BTreeSet<&str> {
        let data = self.receiving.values().map(String::as_str);
        let answers = self.calls_out.values().map(|c| c.server_part.as_str());
        let requests = self.calls_in.values().map(|c| c.client_part.as_str());
        data.chain(answers).chain(requests).collect()
    }
}

/// What a frame's link number stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LinkKind {
    /// A data or parameter link.
    Data(u32),
    /// The requests of call `n`.
    Request(u32),
    /// The answers of call `n`.
    Answer(u32),
}

impl LinkKind {
    /// What the link number `link` stands for.
    pub fn of(link: u32) -> LinkKind {
        match link.checked_sub(calls::CALL_LINKS) {
            None => LinkKind::Data(link),
            Some(k) if k % 2 == 0 => LinkKind::Request(k / 2),
            Some(k) => LinkKind::Answer(k / 2),
        }
    }

    /// The link number.
    pub fn link(self) -> u32 {
        match self {
            LinkKind::Data(n) => n,
            LinkKind::Request(n) => calls::request_link(n),
            LinkKind::Answer(n) => calls::answer_link(n),
        }
    }
}

/// The number a request or answer frame carries (its first 8 bytes): answers name the
/// request they answer by it.
pub fn call_number(bytes: &[u8]) -> Option<u64> {
    bytes.first_chunk::<8>().map(|b| u64::from_le_bytes(*b))
}

/// A network between parts (see the module documentation).
pub trait Network: Send + Sync {
    /// Connects this part for `links`: what arrives goes to `delivery`. In lockstep
    /// (`lockstep`), frames travel with [`Connection::end_instant`] and are taken with
    /// [`Connection::wait_instant`]; running freely, with [`Connection::send`].
    fn open(
        &self,
        links: &PartLinks,
        delivery: Delivery,
        lockstep: bool,
    ) -> Result<Box<dyn Connection>, String>;
}

/// The open network of a running part.
pub trait Connection: Send + Sync {
    /// Running freely: sends a frame to `to_part` now (it may be dropped if the peer
    /// is gone or far behind).
    fn send(&self, to_part: &str, frame: Frame);

    /// Running freely: sends the value `encoder` holds on each data link of `targets`
    /// (link number, reading part) now, like [`send`](Self::send). A network with
    /// buffers of its own (shared memory) encodes a large value straight into one, once
    /// for all the links; by default it goes into a `Vec` of its exact size.
    fn send_encoded(
        &self,
        targets: &[(u32, Arc<str>)],
        encoder: &Encoder<'_>,
    ) -> Result<(), String> {
        send_each(self, targets, encoder)
    }

    /// Running freely: a buffer of `len` bytes for an output to fill whose values go
    /// out on data links of this network (`ferroc_module::lend`): one of its own that
    /// [`send_encoded`](Self::send_encoded) then sends without a copy (shared memory),
    /// or `None` (the default: the output lends plain memory).
    fn lend(&self, len: usize) -> Option<Box<dyn LentBuffer>> {
        let _ = len;
        None
    }

    /// Lockstep: this part finished the instant `nanos` (model time) and sent `frames`
    /// in it; every part it sends to receives them, and the news that the instant is
    /// finished. An error if a part it sends to is gone or `stop` was set.
    fn end_instant(
        &self,
        nanos: u64,
        frames: Vec<(Arc<str>, Frame)>,
        stop: &AtomicBool,
    ) -> Result<(), String>;

    /// Lockstep: waits until every part sending to this one finished the instant
    /// `nanos` and returns what they sent in it. An error if such a part is gone or
    /// `stop` was set.
    fn wait_instant(&self, nanos: u64, stop: &AtomicBool) -> Result<Vec<Frame>, String>;

    /// Closes the connection (after the containers stopped).
    fn close(&self);

    /// What the network has to report now, a line each, for the status line and the
    /// log: a linked part that is gone (`link robot → station: part robot gone since
    /// 3.2 s`). Empty while all is well.
    fn status(&self) -> Vec<String> {
        Vec::new()
    }

    /// How the values of the links this part sends travelled so far (shared memory or
    /// network), and its shared-memory pool, for `ferroc inspect`. Empty by default.
    fn transport(&self) -> TransportUse {
        TransportUse::default()
    }
}

/// How the values this part sends travel ([`Connection::transport`]).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct TransportUse {
    /// Each data link this part sends, by link number.
    pub links: Vec<LinkUse>,
    /// The part's shared-memory pool, if it has one.
    pub pool: Option<PoolUse>,
}

/// The values sent on one data link to another part, by how they went.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct LinkUse {
    /// The link number.
    pub link: u32,
    /// The reading part.
    pub to_part: String,
    /// The writer's module path and output port.
    pub topic: String,
    /// Values sent in a buffer of the shared-memory pool.
    pub shared_memory: u64,
    /// Values sent as bytes over the network (below the threshold, no pool, or a full
    /// pool on a link that may not drop).
    pub network: u64,
    /// Values dropped because the pool was full (`on-full="drop"`).
    pub dropped: u64,
}

/// A shared-memory pool's figures.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PoolUse {
    /// Its size in bytes.
    pub size: u64,
    /// Bytes held now (by values on their way or read in place by readers).
    pub used: u64,
    /// Values of at least this many encoded bytes go into the pool.
    pub threshold: u64,
    /// Buffers that came back from readers whose process is gone (a reader killed
    /// while it held values).
    pub reclaimed: u64,
    /// Buffers a gone reader still counts in that have not come back yet.
    pub gone_held: u64,
}

/// [`Connection::send_encoded`] without buffers of the network's own: the value in a
/// `Vec` of its exact size, one [`Connection::send`] per link.
pub fn send_each<C: Connection + ?Sized>(
    connection: &C,
    targets: &[(u32, Arc<str>)],
    encoder: &Encoder<'_>,
) -> Result<(), String> {
    let bytes = encoder.to_vec()?;
    for (link, to_part) in targets {
        let bytes = bytes.clone();
        connection.send(to_part, Frame { link: *link, bytes });
    }
    Ok(())
}

/// Where a network hands what arrives: the receiving ends of this part.
#[derive(Clone)]
pub struct Delivery {
    inbox: Arc<Inbox>,
}

impl Delivery {
    #[doc(hidden)]
    pub fn new(inbox: Arc<Inbox>) -> Self {
        Delivery { inbox }
    }

    /// Publishes a frame into its receiving end (a value that does not decode is
    /// reported and dropped).
    pub fn deliver(&self, frame: &Frame) {
        self.inbox.deliver(frame);
    }

    /// [`deliver`](Self::deliver) for a value still in the network's own buffer (no
    /// copy into a [`Frame`]).
    pub fn deliver_bytes(&self, link: u32, bytes: &[u8]) {
        self.inbox.deliver_bytes(link, bytes);
    }

    /// [`deliver_bytes`](Self::deliver_bytes) for a value in a buffer it may keep:
    /// its [`Bytes`](ferroc_module::Bytes) fields read `holder` in place, and the
    /// buffer lives as long as they do.
    pub fn deliver_held(&self, link: u32, holder: &Arc<dyn Holder>) {
        self.inbox.deliver_held(link, holder);
    }

    /// [`deliver_held`](Self::deliver_held) of a value that arrived in pieces, the
    /// buffers `parts` one after the other (`Codec::decode_parts`).
    pub fn deliver_parts(&self, link: u32, parts: &[Arc<dyn Holder>]) {
        self.inbox.deliver_parts(link, parts);
    }

    /// Whether this part receives the link `link`.
    pub fn receives(&self, link: u32) -> bool {
        self.inbox.has(link)
    }

    /// Answers the request `number` of call `call` with an error: the service's part
    /// is gone or did not answer in time. The client gets the error value, not a hang.
    pub fn call_failed(&self, call: u32, number: u64, timed_out: bool) {
        let code = if timed_out {
            calls::error_code(ferroc_ports::service::CallError::Timeout)
        } else {
            calls::error_code(ferroc_ports::service::CallError::Disconnected)
        };
        let mut bytes = number.to_le_bytes().to_vec();
        bytes.push(code);
        self.inbox.deliver(&Frame {
            link: calls::answer_link(call),
            bytes,
        });
    }

    /// The part `part` is gone (`true`: its values stop being news, the inputs its
    /// links feed are stale) or back.
    pub fn part_gone(&self, part: &str, gone: bool) {
        self.inbox.part_gone(part, gone);
    }
}
