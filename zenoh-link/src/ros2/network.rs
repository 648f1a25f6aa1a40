//! The ROS 2 nodes of a running part on the network (docs/ros2.md): the runtime's ROS 2
//! ends (`ferroc_runtime::link::ros2`) made into rmw_zenoh nodes, publishers and
//! subscriptions.
//!
//! A published port's frames (its values as the message's CDR, which the runtime
//! writes) become samples of the topic; a subscription's samples (CDR, which the
//! port's receiving end decodes) become frames for that end: delivered at
//! once when running freely, in lockstep kept until the next instant (at most the
//! topic's history depth of them, the newest, so a flood from a foreign node cannot
//! grow memory) and delivered with the frames of the other parts.
//!
//! [`network`] is what `ferroc run` gives a model whose parts are ROS 2 nodes: a
//! session configured as rmw_zenoh configures its nodes (peer, the router at
//! `tcp/localhost:7447`, multicast scouting off), with `ZENOH_SESSION_CONFIG_URI`'s file
//! merged over it as rmw_zenoh reads it.

use super::service::{Ros2Caller, Ros2Server, ServiceSpec, MAX_WAITING};
use super::{NodeSpec, Ros2Node, Ros2Publisher, Ros2Subscriber, TopicSpec};
use crate::shm;
use ferroc_ros2::def::TypeName;
use ferroc_ros2::rmw_zenoh::{Durability, History, Qos, Reliability};
use ferroc_runtime::console;
use ferroc_runtime::link::ros2::{self as ends, Ros2Qos};
use ferroc_runtime::link::transport::{
    send_each, Addresses, Connection, Delivery, Network, PartLinks,
};
use ferroc_runtime::link::Frame;
use ferroc_runtime::module::lend::LentBuffer;
use ferroc_runtime::module::Encoder;
use ferroc_terminal::engine_error;
use std::collections::{BTreeMap, VecDeque};
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex, RwLock};
use zenoh::{Session, Wait};

/// Where rmw_zenoh's nodes find the router (`rmw_zenohd`) by default.
pub const ROUTER: &str = "tcp/localhost:7447";

/// The environment variable naming a Zenoh configuration file, as rmw_zenoh reads it.
pub const CONFIG_ENV: &str = "ZENOH_SESSION_CONFIG_URI";

/// The open ROS 2 nodes of a part (see the module documentation).
pub struct Ros2Ends {
    publishers: BTreeMap<u32, Ros2Publisher>,
    _subscribers: Vec<Ros2Subscriber>,
    /// Service servers by the link number of their answers.
    servers: BTreeMap<u32, Ros2Server>,
    /// Service clients by the link number of their requests.
    callers: BTreeMap<u32, Ros2Caller>,
    _nodes: Vec<Ros2Node>,
    /// In lockstep: what arrived since the last instant.
    arrived: Option<Arc<Arrived>>,
}

impl Ros2Ends {
    /// Declares `nodes` with their topics on `session`; what subscriptions receive goes
    /// to `delivery` (at once), or in lockstep waits for [`Self::take_arrived`].
    pub fn open(
        session: &Session,
        nodes: &[ends::Ros2Node],
        delivery: Delivery,
        lockstep: bool,
    ) -> Result<Ros2Ends, String> {
        let registry = Arc::new(super::interfaces::registry(nodes)?);
        let arrived = lockstep.then(Arc::<Arrived>::default);
        let mut open = Ros2Ends {
            publishers: BTreeMap::new(),
            _subscribers: Vec::new(),
            servers: BTreeMap::new(),
            callers: BTreeMap::new(),
            _nodes: Vec::new(),
            arrived,
        };
        let mut next_id = 0;
        for n in nodes {
            let spec = NodeSpec {
                domain: n.domain,
                namespace: n.namespace.clone(),
                name: n.name.clone(),
            };
            let node = Ros2Node::declare(session, Arc::clone(&registry), &spec, next_id)?;
            for t in &n.topics {
                open.add_topic(&node, t, &delivery)?;
            }
            for service in &n.services {
                open.add_server(&node, service, &delivery)?;
            }
            for client in &n.clients {
                open.add_caller(&node, client, &delivery)?;
            }
            next_id = node.next_id();
            open._nodes.push(node);
        }
        Ok(open)
    }

    fn add_topic(
        &mut self,
        node: &Ros2Node,
        t: &ends::Ros2Topic,
        delivery: &Delivery,
    ) -> Result<(), String> {
        let ty = TypeName::parse(&t.message).ok_or_else(|| {
            format!(
                "`{}` is not a ROS 2 message type (package/msg/Name) of the topic `{}`",
                t.message, t.topic
            )
        })?;
        let spec = TopicSpec {
            topic: t.topic.clone(),
            ty,
            qos: qos(t.qos),
            field: t.field.clone(),
        };
        if t.publish {
            self.publishers
                .insert(ends::link(t.id), node.publisher(spec)?);
            return Ok(());
        }
        let (link, depth) = (ends::link(t.id), t.qos.depth.max(1) as usize);
        let arrived = self.arrived.clone();
        let delivery = delivery.clone();
        let subscriber = node.subscriber(spec, move |bytes| match &arrived {
            Some(queue) => queue.push(link, bytes, depth),
            None => delivery.deliver_bytes(link, &bytes),
        })?;
        self._subscribers.push(subscriber);
        Ok(())
    }

    /// A server of the module's service `s`: its requests go to the stand-in client on
    /// the service's request link (in lockstep at the next instant, every one: each
    /// holds one of the server's [`MAX_WAITING`] places until it is answered, so one
    /// dropped here would keep its place, and its caller waiting, for ever; the
    /// module's request queue refuses what it cannot take, with an answer).
    fn add_server(
        &mut self,
        node: &Ros2Node,
        s: &ends::Ros2Service,
        delivery: &Delivery,
    ) -> Result<(), String> {
        let spec = service_spec(s)?;
        let link = ends::request_link(s.id);
        let (arrived, delivery) = (self.arrived.clone(), delivery.clone());
        let server = node.service_server(spec, move |bytes| match &arrived {
            Some(queue) => queue.push(link, bytes, MAX_WAITING),
            None => delivery.deliver_bytes(link, &bytes),
        })?;
        self.servers.insert(ends::answer_link(s.id), server);
        Ok(())
    }

    /// A client of the ROS 2 service `c` for a module's client: its answers go to the
    /// stand-in service on the answer link (in lockstep at the next instant, every one).
    fn add_caller(
        &mut self,
        node: &Ros2Node,
        c: &ends::Ros2Service,
        delivery: &Delivery,
    ) -> Result<(), String> {
        let spec = service_spec(c)?;
        let link = ends::answer_link(c.id);
        let (arrived, delivery) = (self.arrived.clone(), delivery.clone());
        // Every answer is kept for the next instant: each is the one answer (or time-out)
        // of a call the module made, whose caller waits for it, so they are as many as
        // its calls in flight, never more (a server replying twice is answered once).
        let caller = node.service_client(spec, move |bytes| match &arrived {
            Some(queue) => queue.push(link, bytes, usize::MAX),
            None => delivery.deliver_bytes(link, &bytes),
        })?;
        self.callers.insert(ends::request_link(c.id), caller);
        Ok(())
    }

    /// Whether `link` is a published topic of these nodes.
    pub fn publishes(&self, link: u32) -> bool {
        self.publishers.contains_key(&link)
    }

    /// Publishes a frame of a published port (its value as the message's CDR, sent as
    /// it is); the frame back when it is not for a ROS 2 end. A sample that cannot be
    /// sent is reported (throttled, naming the topic).
    pub fn publish(&self, frame: Frame) -> Result<(), Frame> {
        if let Some(caller) = self.callers.get(&frame.link) {
            if let Err(why) = caller.call(&frame.bytes) {
                console::report(&service_warning(&caller.spec().name, &why));
            }
            return Ok(());
        }
        if let Some(server) = self.servers.get(&frame.link) {
            if let Err(why) = server.answer(&frame.bytes) {
                console::report(&service_warning(&server.spec().name, &why));
            }
            return Ok(());
        }
        let Some(publisher) = self.publishers.get(&frame.link) else {
            return Err(frame);
        };
        if let Err(why) = publisher.publish_cdr(frame.bytes) {
            console::report(&format!(
                "warning: a value was not published on the ROS 2 topic `{}`: {why}",
                publisher.spec().topic
            ));
        }
        Ok(())
    }

    /// In lockstep: the samples that arrived since the last call, as frames in the
    /// order they arrived per topic.
    pub fn take_arrived(&self) -> Vec<Frame> {
        self.arrived.as_ref().map_or_else(Vec::new, |a| a.take())
    }
}

/// The warning about a request or answer of the ROS 2 service `name` that went wrong
/// (`why` does not name the service again).
fn service_warning(name: &str, why: &str) -> String {
    format!("warning: ROS 2 service `{name}`: {why}")
}

/// What the wire needs of a service or client end.
fn service_spec(s: &ends::Ros2Service) -> Result<ServiceSpec, String> {
    let ty = TypeName::parse(&s.service)
        .filter(|t| t.kind == "srv")
        .ok_or_else(|| {
            format!(
                "`{}` is not a ROS 2 service type (package/srv/Name) of the service `{}`",
                s.service, s.name
            )
        })?;
    Ok(ServiceSpec {
        name: s.name.clone(),
        ty,
        request_field: s.request_field.clone(),
        response_field: s.response_field.clone(),
    })
}

/// The QoS of a topic end on the wire.
fn qos(q: Ros2Qos) -> Qos {
    Qos {
        reliability: if q.reliable {
            Reliability::Reliable
        } else {
            Reliability::BestEffort
        },
        durability: if q.transient_local {
            Durability::TransientLocal
        } else {
            Durability::Volatile
        },
        history: History::KeepLast(q.depth),
    }
}

/// Samples kept for the next lockstep instant, per link at most its history depth.
#[derive(Default)]
struct Arrived {
    queues: Mutex<BTreeMap<u32, VecDeque<Vec<u8>>>>,
}

impl Arrived {
    fn push(&self, link: u32, bytes: Vec<u8>, depth: usize) {
        let mut queues = self.queues.lock().unwrap_or_else(|e| e.into_inner());
        let queue = queues.entry(link).or_default();
        if queue.len() >= depth {
            queue.pop_front();
        }
        queue.push_back(bytes);
    }

    fn take(&self) -> Vec<Frame> {
        let mut queues = self.queues.lock().unwrap_or_else(|e| e.into_inner());
        let mut frames = Vec::new();
        for (&link, queue) in queues.iter_mut() {
            frames.extend(queue.drain(..).map(|bytes| Frame { link, bytes }));
        }
        frames
    }
}

/// A part's connection with its ROS 2 nodes: ROS 2 frames go to the nodes, the rest
/// to the connection to the other parts (if the part has one).
pub struct WithRos2 {
    inner: Option<Box<dyn Connection>>,
    ends: RwLock<Option<Ros2Ends>>,
    /// The session the nodes were opened on when it is this connection's own.
    session: Option<Session>,
}

impl WithRos2 {
    /// `ends` beside `inner`; `session` is closed with the connection when given.
    pub fn new(
        inner: Option<Box<dyn Connection>>,
        ends: Ros2Ends,
        session: Option<Session>,
    ) -> Self {
        WithRos2 {
            inner,
            ends: RwLock::new(Some(ends)),
            session,
        }
    }

    /// Publishes `frame` if it is a ROS 2 end's; the frame back if it is not.
    fn publish(&self, frame: Frame) -> Result<(), Frame> {
        let ends = self.ends.read().unwrap_or_else(|e| e.into_inner());
        match ends.as_ref() {
            Some(e) => e.publish(frame),
            None => Err(frame),
        }
    }
}

impl Connection for WithRos2 {
    fn send(&self, to_part: &str, frame: Frame) {
        if let (Err(frame), Some(inner)) = (self.publish(frame), &self.inner) {
            inner.send(to_part, frame);
        }
    }

    /// Values for other parts only go to the parts' network as they are (encoded into
    /// its shared memory, once for all links); a ROS 2 topic's frame goes by `send`.
    fn send_encoded(
        &self,
        targets: &[(u32, Arc<str>)],
        encoder: &Encoder<'_>,
    ) -> Result<(), String> {
        let ends = self.ends.read().unwrap_or_else(|e| e.into_inner());
        let ros2 = (ends.as_ref()).is_some_and(|e| targets.iter().any(|(l, _)| e.publishes(*l)));
        drop(ends);
        match &self.inner {
            Some(inner) if !ros2 => inner.send_encoded(targets, encoder),
            _ => send_each(self, targets, encoder),
        }
    }

    /// A buffer of the parts' network (its shared memory) for an output whose readers
    /// are all other parts; a ROS 2 topic's end reads in this part, so its outputs never
    /// ask.
    fn lend(&self, len: usize) -> Option<Box<dyn LentBuffer>> {
        self.inner.as_ref()?.lend(len)
    }

    fn end_instant(
        &self,
        nanos: u64,
        frames: Vec<(Arc<str>, Frame)>,
        stop: &AtomicBool,
    ) -> Result<(), String> {
        let others: Vec<(Arc<str>, Frame)> = frames
            .into_iter()
            .filter_map(|(to, frame)| self.publish(frame).err().map(|f| (to, f)))
            .collect();
        match &self.inner {
            Some(inner) => inner.end_instant(nanos, others, stop),
            None => Ok(()),
        }
    }

    fn wait_instant(&self, nanos: u64, stop: &AtomicBool) -> Result<Vec<Frame>, String> {
        let mut frames = match &self.inner {
            Some(inner) => inner.wait_instant(nanos, stop)?,
            None => Vec::new(),
        };
        let ends = self.ends.read().unwrap_or_else(|e| e.into_inner());
        if let Some(ends) = ends.as_ref() {
            frames.extend(ends.take_arrived());
        }
        Ok(frames)
    }

    fn close(&self) {
        if let Some(inner) = &self.inner {
            inner.close();
        }
        // The nodes' tokens go before the session does: ROS 2 sees them leave.
        drop(self.ends.write().unwrap_or_else(|e| e.into_inner()).take());
        if let Some(session) = &self.session {
            let _ = session.close().wait();
        }
    }

    fn status(&self) -> Vec<String> {
        self.inner.as_ref().map_or_else(Vec::new, |i| i.status())
    }

    fn transport(&self) -> ferroc_runtime::link::transport::TransportUse {
        self.inner
            .as_ref()
            .map(|i| i.transport())
            .unwrap_or_default()
    }
}

/// The network of `ferroc run` for a model whose parts are ROS 2 nodes (every part
/// runs in one process, so only the nodes go on the network).
pub struct Ros2Network {
    config: zenoh::Config,
    /// Whose configuration it is, for the warning where shared memory is not usable.
    whose: shm::probe::Whose,
    /// The computer gives no usable shared memory: the session opens without it (after
    /// one warning).
    no_shm: AtomicBool,
}

impl Ros2Network {
    /// Configured as rmw_zenoh configures a node, with the JSON5 file `file` merged
    /// over it (what the file sets wins).
    pub fn new(file: Option<&Path>) -> Result<Ros2Network, String> {
        Self::configured(file, &format!("{CONFIG_ENV}="))
    }

    /// [`Self::new`], with errors about `file` naming it as `named` says
    /// (`--zenoh-config ` or `ZENOH_SESSION_CONFIG_URI=`).
    fn configured(file: Option<&Path>, named: &str) -> Result<Ros2Network, String> {
        let addresses = Addresses {
            part: "ros2".into(),
            listen: "tcp/localhost:0".into(),
            peers: [("rmw_zenohd".to_string(), ROUTER.to_string())].into(),
        };
        let mut config = crate::config::config(&addresses, file)
            .map_err(|e| e.replacen("--zenoh-config ", named, 1))?;
        super::durability::session_settings(&mut config)?;
        let whose = shm::probe::Whose {
            travels: "the ROS 2 nodes' messages to others on this computer",
            config: match named.trim_end() {
                "--zenoh-config" => "--zenoh-config",
                _ => "the file ZENOH_SESSION_CONFIG_URI names",
            },
        };
        Ok(Ros2Network {
            config,
            whose,
            no_shm: AtomicBool::new(false),
        })
    }
}

/// [`Ros2Network`] with the file `ZENOH_SESSION_CONFIG_URI` names, if set: what a ROS 2
/// runner gives the run (`ferroc_runner::main_ros2`).
pub fn network() -> Result<Arc<dyn Network>, String> {
    network_from(None)
}

/// [`Ros2Network`] with the file `file` (a bundle program's `--zenoh-config`), else
/// the one `ZENOH_SESSION_CONFIG_URI` names, if set: what a bundle's program whose part
/// is a ROS 2 node but has no links to other parts runs on.
pub fn network_from(file: Option<&Path>) -> Result<Arc<dyn Network>, String> {
    let network = match file {
        Some(file) => Ros2Network::configured(Some(file), "--zenoh-config "),
        None => {
            let from_env = std::env::var_os(CONFIG_ENV).filter(|f| !f.is_empty());
            Ros2Network::new(from_env.as_deref().map(Path::new))
        }
    };
    Ok(Arc::new(network?))
}

impl Network for Ros2Network {
    fn open(
        &self,
        links: &PartLinks,
        delivery: Delivery,
        lockstep: bool,
    ) -> Result<Box<dyn Connection>, String> {
        if links.has_parts() {
            return Err(
                "links to other programs need the part's own network; this one carries only \
                 the ROS 2 nodes of `ferroc run` (help: run the parts as a bundle, \
                 `ferroc bundle`)"
                    .into(),
            );
        }
        // Where the computer cannot give shared memory, Zenoh would refuse to open the
        // session with it: off, after one warning for the run (docs/zenoh.md).
        let mut config = self.config.clone();
        shm::probe::off_where_unusable(&mut config, &self.no_shm, self.whose)?;
        let session = zenoh::open(config).wait().map_err(|e| {
            format!(
                "the ROS 2 nodes cannot open their Zenoh session: {}",
                engine_error(&e)
            )
        })?;
        match Ros2Ends::open(&session, &links.ros2, delivery, lockstep) {
            Ok(ends) => Ok(Box::new(WithRos2::new(None, ends, Some(session)))),
            Err(why) => {
                let _ = session.close().wait();
                Err(why)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flood_in_lockstep_keeps_only_the_newest_depth_samples_of_each_topic() {
        let arrived = Arrived::default();
        for i in 0..100_000u32 {
            arrived.push(7, i.to_string().into_bytes(), 10);
        }
        arrived.push(3, b"true".to_vec(), 10);
        let frames = arrived.take();
        assert_eq!(frames.len(), 11);
        assert_eq!(
            (frames[0].link, frames[0].bytes.as_slice()),
            (3, &b"true"[..])
        );
        assert_eq!(frames[1].bytes, b"99990");
        assert_eq!(frames[10].bytes, b"99999");
        assert!(arrived.take().is_empty(), "taken once");
    }

    /// A request the module's full request queue refused: the service named once.
    #[test]
    fn a_refused_request_s_warning_names_the_service_once() {
        let why = super::super::service::not_answered(&ferroc_runtime::link::calls::error_of(4));
        assert_eq!(
            service_warning("/switch_bot/set_enabled", &why),
            "warning: ROS 2 service `/switch_bot/set_enabled`: a request was not answered: \
             the service's request queue is full"
        );
    }

    #[test]
    fn the_model_s_qos_is_rmw_zenoh_s() {
        let best_effort = Ros2Qos {
            reliable: false,
            transient_local: false,
            depth: 5,
        };
        assert_eq!(qos(best_effort).keyexpr(), "2::,5:,:,:,,");
        assert_eq!(qos(Ros2Qos::default()), Qos::default());
    }

    /// Without a file, a node's session is rmw_zenoh's: peer, the router at
    /// `tcp/localhost:7447`, listening on `tcp/localhost:0`, no multicast, time stamps
    /// on; a file's `connect` replaces the router (peer to peer, another router).
    #[test]
    fn the_session_is_rmw_zenoh_s_unless_a_file_says_otherwise() {
        let get = |n: &Ros2Network, key: &str| n.config.get_json(key).unwrap();
        let default = Ros2Network::new(None).unwrap();
        assert_eq!(get(&default, "mode"), "\"peer\"");
        assert_eq!(
            get(&default, "connect/endpoints"),
            "[\"tcp/localhost:7447\"]"
        );
        assert!(get(&default, "listen/endpoints").contains("tcp/localhost:0"));
        assert_eq!(get(&default, "scouting/multicast/enabled"), "false");
        assert_eq!(get(&default, "timestamping/enabled"), "true");
        let dir = std::env::temp_dir().join(format!("ferroc-ros2-peer-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("peer.json5");
        std::fs::write(
            &file,
            "{ connect: { endpoints: [\"tcp/192.168.1.20:7447\"] } }",
        )
        .unwrap();
        let merged = Ros2Network::new(Some(&file)).unwrap();
        let connect = get(&merged, "connect/endpoints");
        assert_eq!(
            connect, "[\"tcp/192.168.1.20:7447\"]",
            "no router left: {connect}"
        );
        assert_eq!(get(&merged, "scouting/multicast/enabled"), "false");
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_bad_configuration_file_names_the_environment_variable() {
        let dir = std::env::temp_dir().join(format!("ferroc-ros2-cfg-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("bad.json5");
        std::fs::write(&file, "{ mode: ").unwrap();
        let err = Ros2Network::new(Some(&file)).err().unwrap();
        assert!(err.starts_with("ZENOH_SESSION_CONFIG_URI="), "{err}");
        assert!(Ros2Network::new(None).is_ok());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
