//! The network between parts: one TCP stream per sending part and receiving part.
//!
//! Each part listens on its own address for the parts that send to it, and connects
//! to the parts it sends to (retrying until they are up, so the programs may start in
//! any order). A stream starts with the sender's part name and then carries messages:
//! a 4-byte little-endian length, a tag byte and the body. Frames carry values; in
//! lockstep a tick after each instant of model time says "everything I sent up to this
//! instant is on its way", which is all a reader waits for.
//!
//! Nothing a peer sends can crash a part: an oversized or unknown message ends that
//! stream with a warning.

use super::{Frame, Inbox};
use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::io::{BufReader, BufWriter, Read, Write};
use std::net::{TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{self, Receiver, Sender, SyncSender, TrySendError};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Where this part listens and where the others are.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Network {
    /// This part's name.
    pub part: String,
    /// The address to listen on for parts that send to this one (`0.0.0.0:47801`).
    pub listen: String,
    /// Every other part's address (`station` → `base-pc:47802`).
    pub peers: BTreeMap<String, String>,
}

/// The largest message accepted (a big map is a few MiB).
const MAX_MESSAGE: usize = 64 << 20;
/// How many frames may wait for a slow or absent peer before new ones are dropped.
const QUEUE: usize = 4096;

/// One message on a stream.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Message {
    /// The sender's part name, first on every stream.
    Hello(String),
    /// A value.
    Frame(Frame),
    /// Lockstep: the sender has finished this instant (nanoseconds of model time).
    Tick(u64),
    /// The sender stops.
    Bye,
}

/// Writes one message.
pub fn write_message(out: &mut impl Write, message: &Message) -> std::io::Result<()> {
    let (tag, body): (u8, Vec<u8>) = match message {
        Message::Hello(name) => (1, name.as_bytes().to_vec()),
        Message::Frame(f) => {
            let mut b = Vec::with_capacity(4 + f.bytes.len());
            b.extend_from_slice(&f.link.to_le_bytes());
            b.extend_from_slice(&f.bytes);
            (2, b)
        }
        Message::Tick(t) => (3, t.to_le_bytes().to_vec()),
        Message::Bye => (4, Vec::new()),
    };
    let len = u32::try_from(body.len() + 1).map_err(|_| std::io::ErrorKind::InvalidInput)?;
    out.write_all(&len.to_le_bytes())?;
    out.write_all(&[tag])?;
    out.write_all(&body)
}

/// Reads one message; `Ok(None)` at the end of the stream.
pub fn read_message(input: &mut impl Read) -> Result<Option<Message>, String> {
    let mut len = [0u8; 4];
    match input.read_exact(&mut len) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => return Ok(None),
        Err(e) => return Err(e.to_string()),
    }
    let len = u32::from_le_bytes(len) as usize;
    if len == 0 || len > MAX_MESSAGE {
        return Err(format!(
            "a message of {len} bytes (at most {MAX_MESSAGE} are accepted)"
        ));
    }
    let mut body = vec![0u8; len];
    input.read_exact(&mut body).map_err(|e| e.to_string())?;
    let (tag, body) = (body[0], &body[1..]);
    let fixed = |n: usize| -> Result<&[u8], String> {
        (body.len() == n)
            .then_some(body)
            .ok_or_else(|| format!("a message of kind {tag} with {} bytes", body.len()))
    };
    Ok(Some(match tag {
        1 => Message::Hello(
            String::from_utf8(body.to_vec()).map_err(|_| "a part name that is not UTF-8")?,
        ),
        2 if body.len() >= 4 => Message::Frame(Frame {
            link: u32::from_le_bytes([body[0], body[1], body[2], body[3]]),
            bytes: body[4..].to_vec(),
        }),
        3 => Message::Tick(u64::from_le_bytes(
            fixed(8)?.try_into().map_err(|_| "a short tick")?,
        )),
        4 => Message::Bye,
        _ => return Err(format!("an unknown message of kind {tag}")),
    }))
}

/// The streams to the parts this one sends to, each with its own thread.
pub(crate) struct Outgoing {
    peers: BTreeMap<String, (SyncSender<Message>, JoinHandle<()>)>,
    dropped: Arc<AtomicU64>,
}

impl Outgoing {
    /// Starts a sender thread for each part in `to` (connecting in the background).
    pub(crate) fn start(
        network: &Network,
        to: &BTreeSet<String>,
        stop: &Arc<AtomicBool>,
        reconnect: bool,
    ) -> Result<Self, String> {
        let mut peers = BTreeMap::new();
        for part in to {
            let address = network.peers.get(part).cloned().ok_or_else(|| {
                format!("no address for the part `{part}`; give one with --peer {part}=HOST:PORT")
            })?;
            let (tx, rx) = mpsc::sync_channel(QUEUE);
            let (me, part_name, stop) = (network.part.clone(), part.clone(), Arc::clone(stop));
            let join = std::thread::Builder::new()
                .name(format!("to {part}").chars().take(15).collect())
                .spawn(move || send_loop(&me, &part_name, &address, &rx, &stop, reconnect))
                .map_err(|e| format!("cannot start the sender to `{part}`: {e}"))?;
            peers.insert(part.clone(), (tx, join));
        }
        Ok(Outgoing {
            peers,
            dropped: Arc::default(),
        })
    }

    /// Running freely: queues a frame, dropping it if the peer is far behind.
    pub(crate) fn send(&self, to_part: &str, frame: Frame) {
        if let Some((tx, _)) = self.peers.get(to_part) {
            if let Err(TrySendError::Full(_)) = tx.try_send(Message::Frame(frame)) {
                self.dropped.fetch_add(1, Ordering::Relaxed);
            }
        }
    }

    /// Lockstep: queues a message, waiting while the queue is full.
    pub(crate) fn send_waiting(&self, to_part: &str, message: Message) {
        if let Some((tx, _)) = self.peers.get(to_part) {
            let _ = tx.send(message);
        }
    }

    /// The parts this one sends to.
    pub(crate) fn parts(&self) -> impl Iterator<Item = &str> {
        self.peers.keys().map(String::as_str)
    }

    /// Says goodbye to every peer and waits (a little) for the queues to drain.
    pub(crate) fn close(&self) {
        let deadline = Instant::now() + Duration::from_secs(2);
        for (tx, join) in self.peers.values() {
            let _ = tx.try_send(Message::Bye);
            while !join.is_finished() && Instant::now() < deadline {
                std::thread::sleep(Duration::from_millis(5));
            }
        }
        let dropped = self.dropped.load(Ordering::Relaxed);
        if dropped > 0 {
            eprintln!("warning: {dropped} values were dropped because a part did not keep up");
        }
    }
}

/// Connects to the part (retrying until it is up or `stop` is set) and introduces
/// this one; `None` once stopped.
fn connect(me: &str, part: &str, address: &str, stop: &AtomicBool) -> Option<BufWriter<TcpStream>> {
    let started = Instant::now();
    let mut told = false;
    loop {
        match TcpStream::connect(address) {
            Ok(stream) => {
                let _ = stream.set_nodelay(true);
                let mut out = BufWriter::new(stream);
                let hello = write_message(&mut out, &Message::Hello(me.to_owned()));
                if hello.and_then(|()| out.flush()).is_ok() {
                    return Some(out);
                }
            }
            Err(e) if !told && started.elapsed() > Duration::from_secs(5) => {
                told = true;
                crate::console::line(&format!(
                    "waiting for the part `{part}` at {address} ({e}); is it running?"
                ));
            }
            Err(_) => {}
        }
        if stop.load(Ordering::Relaxed) {
            return None;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// Sends what the channel brings. Running freely, a lost connection is made again
/// (what was sent meanwhile is lost, as over a wireless link); in lockstep the
/// peer has stopped, so this ends.
fn send_loop(
    me: &str,
    part: &str,
    address: &str,
    rx: &Receiver<Message>,
    stop: &AtomicBool,
    reconnect: bool,
) {
    let Some(mut out) = connect(me, part, address, stop) else {
        return;
    };
    while let Ok(first) = rx.recv() {
        let mut batch = vec![first];
        batch.extend(rx.try_iter());
        let bye = batch.contains(&Message::Bye);
        let written = batch.iter().try_for_each(|m| write_message(&mut out, m));
        if let Err(e) = written.and_then(|()| out.flush()) {
            if bye || !reconnect {
                crate::console::line(&format!("warning: lost the connection to `{part}`: {e}"));
                return;
            }
            crate::console::line(&format!(
                "warning: lost the connection to `{part}` ({e}); connecting again"
            ));
            match connect(me, part, address, stop) {
                Some(again) => out = again,
                None => return,
            }
            continue;
        }
        if bye {
            return;
        }
    }
    let _ = write_message(&mut out, &Message::Bye).and_then(|()| out.flush());
}

/// What a receiving thread does with what arrives.
#[derive(Clone)]
pub(crate) enum Sink {
    /// Running freely: publish at once.
    Deliver(Arc<Inbox>),
    /// Lockstep: hand to the driver, which applies it at the right instant.
    Queue(Sender<(String, Message)>),
}

/// Listens on `network.listen` and receives from the parts in `from`.
pub(crate) fn listen(
    network: &Network,
    from: BTreeSet<String>,
    sink: Sink,
    stop: &Arc<AtomicBool>,
) -> Result<(), String> {
    let listener = TcpListener::bind(&network.listen)
        .map_err(|e| format!("cannot listen on {}: {e}", network.listen))?;
    listener
        .set_nonblocking(true)
        .map_err(|e| format!("cannot listen on {}: {e}", network.listen))?;
    let stop = Arc::clone(stop);
    std::thread::Builder::new()
        .name("links in".into())
        .spawn(move || {
            while !stop.load(Ordering::Relaxed) {
                match listener.accept() {
                    Ok((stream, _)) => {
                        let (from, sink) = (from.clone(), sink.clone());
                        let stop = Arc::clone(&stop);
                        let _ = std::thread::Builder::new()
                            .name("link reader".into())
                            .spawn(move || receive(stream, &from, &sink, &stop));
                    }
                    Err(_) => std::thread::sleep(Duration::from_millis(20)),
                }
            }
        })
        .map_err(|e| format!("cannot start the receiver: {e}"))?;
    Ok(())
}

fn receive(stream: TcpStream, from: &BTreeSet<String>, sink: &Sink, stop: &AtomicBool) {
    let _ = stream.set_nonblocking(false);
    // Wake now and then to see the stop flag: a stopped part must close its end, so
    // that a sender notices and connects to whoever listens next.
    let _ = stream.set_read_timeout(Some(Duration::from_millis(100)));
    let mut input = BufReader::new(UntilStopped { stream, stop });
    let peer = match read_message(&mut input) {
        Ok(Some(Message::Hello(name))) if from.contains(&name) => name,
        Ok(Some(Message::Hello(name))) => {
            crate::console::line(&format!(
                "warning: the part `{name}` connected, but it sends nothing to this part; ignored"
            ));
            return;
        }
        _ => return, // not a ferroc peer
    };
    loop {
        let message = match read_message(&mut input) {
            Ok(Some(m)) => m,
            Ok(None) => Message::Bye,
            Err(_) if stop.load(Ordering::Relaxed) => Message::Bye,
            Err(why) => {
                crate::console::line(&format!(
                    "warning: the part `{peer}` sent {why}; its connection is closed"
                ));
                Message::Bye
            }
        };
        let bye = message == Message::Bye;
        match (sink, message) {
            (Sink::Deliver(inbox), Message::Frame(frame)) => inbox.deliver(&frame),
            (Sink::Deliver(_), _) => {}
            (Sink::Queue(tx), message) => {
                if tx.send((peer.clone(), message)).is_err() {
                    return;
                }
            }
        }
        if bye {
            return;
        }
    }
}

/// A stream whose reads wait through timeouts until `stop` is set.
struct UntilStopped<'a> {
    stream: TcpStream,
    stop: &'a AtomicBool,
}

impl Read for UntilStopped<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        loop {
            if self.stop.load(Ordering::Relaxed) {
                return Err(std::io::Error::other("this part stops"));
            }
            match self.stream.read(buf) {
                Err(e)
                    if matches!(
                        e.kind(),
                        std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                    ) => {}
                other => return other,
            }
        }
    }
}

/// Lockstep: sorts what the receiving threads hand over by sender, so the driver can
/// take exactly what each sender sent up to an instant.
pub(crate) struct Ticks {
    rx: Receiver<(String, Message)>,
    from: BTreeSet<String>,
    queues: BTreeMap<String, VecDeque<Message>>,
}

impl Ticks {
    pub(crate) fn new(rx: Receiver<(String, Message)>, from: BTreeSet<String>) -> Self {
        Ticks {
            rx,
            from,
            queues: BTreeMap::new(),
        }
    }

    /// Waits until every sending part finished the instant `tick` and returns what they
    /// sent up to it. An error if a part stopped or `stop` was set.
    pub(crate) fn frames_until(
        &mut self,
        tick: u64,
        stop: &AtomicBool,
    ) -> Result<Vec<Frame>, String> {
        let started = Instant::now();
        let mut told = false;
        loop {
            let missing: Vec<&String> = self
                .from
                .iter()
                .filter(|p| {
                    !self.queues.get(*p).is_some_and(|q| {
                        q.iter()
                            .any(|m| matches!(m, Message::Tick(t) if *t >= tick))
                    })
                })
                .collect();
            if let Some(gone) = missing.iter().find(|p| {
                self.queues
                    .get(**p)
                    .is_some_and(|q| q.contains(&Message::Bye))
            }) {
                return Err(format!("the part `{gone}` stopped"));
            }
            if missing.is_empty() {
                break;
            }
            if stop.load(Ordering::Relaxed) {
                return Err("interrupted".into());
            }
            if !told && started.elapsed() > Duration::from_secs(5) {
                told = true;
                let names: Vec<String> = missing.iter().map(|p| format!("`{p}`")).collect();
                crate::console::line(&format!(
                    "waiting for the part(s) {} to reach the same instant",
                    names.join(", ")
                ));
            }
            match self.rx.recv_timeout(Duration::from_millis(50)) {
                Ok((peer, m)) => self.queues.entry(peer).or_default().push_back(m),
                Err(mpsc::RecvTimeoutError::Timeout) => {}
                Err(mpsc::RecvTimeoutError::Disconnected) => {
                    return Err("the network receiver ended".into())
                }
            }
        }
        let mut frames = Vec::new();
        for queue in self.queues.values_mut() {
            while let Some(m) = queue.pop_front() {
                match m {
                    Message::Frame(f) => frames.push(f),
                    Message::Tick(t) if t >= tick => break,
                    _ => {}
                }
            }
        }
        Ok(frames)
    }
}
