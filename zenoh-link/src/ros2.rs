//! A part as a ROS 2 node on rmw_zenoh's wire (issue 29, docs/ros2.md): from the part's
//! own Zenoh session, the liveliness tokens by which ROS 2 discovers a node and its
//! publishers and subscriptions, samples on rmw_zenoh's topic keys with CDR payloads and
//! rmw_zenoh's attachment, and subscriptions that hand on what ROS 2 nodes publish. The
//! formats are `ferroc_ros2::rmw_zenoh`'s; the samples are CDR the runtime writes
//! straight from a port's value and reads straight into it (`Codec::ros2_encode`,
//! `ferroc_ros2::serde_cdr`), so here they are sent and received as they are.
//!
//! A sample without rmw_zenoh's attachment, or with a short one, is reported here
//! (throttled per topic and kind, naming the topic) and dropped; so is a sample of the
//! topic's type under another type hash, which rmw_zenoh would never deliver; a
//! malformed CDR sample is reported and dropped by the port's receiving end the same
//! way: the part keeps running and other topics keep flowing.

use durability::{TopicPublisher, TopicSubscriber};
use ferroc_ros2::def::TypeName;
use ferroc_ros2::rmw_zenoh::{self, Attachment, EntityKind, NodeInfo, Qos, TopicInfo};
use ferroc_ros2::{cdr, Registry};
use ferroc_runtime::console;
use std::sync::atomic::{AtomicI64, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{SystemTime, UNIX_EPOCH};
use zenoh::liveliness::LivelinessToken;
use zenoh::pubsub::Subscriber;
use zenoh::{Session, Wait};

pub mod durability;
pub mod interfaces;
pub mod network;
pub mod service;
mod service_hash;

/// A ROS 2 node: its name, namespace and domain.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NodeSpec {
    pub domain: u32,
    /// Absolute (`/` when none).
    pub namespace: String,
    pub name: String,
}

/// A topic end: the fully qualified topic, the message type, the QoS, and the part of
/// the message the port carries (`None`: all of it).
#[derive(Clone, Debug, PartialEq)]
pub struct TopicSpec {
    pub topic: String,
    pub ty: TypeName,
    pub qos: Qos,
    pub field: Option<String>,
}

/// The node of this part: its token and the counter of its entities' ids.
pub struct Ros2Node {
    session: Session,
    registry: Arc<Registry>,
    info: NodeInfo,
    next_id: AtomicU64,
    _token: LivelinessToken,
}

impl Ros2Node {
    /// Declares the node `spec` on `session` (its liveliness token, `NN`). `node_id` is
    /// the node's number within the session (rmw_zenoh counts nodes and entities of a
    /// context from 0); the node's entities take the ids after it.
    pub fn declare(
        session: &Session,
        registry: Arc<Registry>,
        spec: &NodeSpec,
        node_id: u64,
    ) -> Result<Ros2Node, String> {
        let info = NodeInfo {
            domain: spec.domain,
            zid: session.zid().to_string(),
            node_id,
            enclave: "/".into(),
            namespace: spec.namespace.clone(),
            name: spec.name.clone(),
        };
        let key = rmw_zenoh::liveliness_key(&info, EntityKind::Node, node_id, None);
        let token = token(session, &key, &spec.name)?;
        Ok(Ros2Node {
            session: session.clone(),
            registry,
            info,
            next_id: AtomicU64::new(node_id + 1),
            _token: token,
        })
    }

    /// The id the next node of the session takes (after this node's entities).
    pub fn next_id(&self) -> u64 {
        self.next_id.load(Ordering::Relaxed)
    }

    /// The topic's key and its entity's liveliness key.
    fn keys(&self, spec: &TopicSpec, kind: EntityKind) -> Result<(String, String, u64), String> {
        let hash = ferroc_ros2::hash::rihs01(&self.registry, &spec.ty)
            .ok_or_else(|| format!("unknown message type `{}`", spec.ty))?;
        let key = rmw_zenoh::topic_key(self.info.domain, &spec.topic, &spec.ty, &hash);
        let id = self.next_id.fetch_add(1, Ordering::Relaxed);
        let topic = TopicInfo {
            name: spec.topic.clone(),
            ty: spec.ty.clone(),
            hash,
            qos: spec.qos,
        };
        let live = rmw_zenoh::liveliness_key(&self.info, kind, id, Some(&topic));
        Ok((key, live, id))
    }

    /// A publisher of `spec` (its token `MP` and a Zenoh publisher on the topic key).
    pub fn publisher(&self, spec: TopicSpec) -> Result<Ros2Publisher, String> {
        let (key, live, _) = self.keys(&spec, EntityKind::Publisher)?;
        let token = token(&self.session, &live, &spec.topic)?;
        let publisher = TopicPublisher::declare(&self.session, key, &spec.qos)
            .map_err(|e| format!("cannot publish the ROS 2 topic `{}`: {e}", spec.topic))?;
        Ok(Ros2Publisher {
            registry: Arc::clone(&self.registry),
            gid: rmw_zenoh::gid_of(&live),
            spec,
            publisher,
            sequence: AtomicI64::new(0),
            _token: token,
        })
    }

    /// A subscription of `spec` (its token `MS` and a Zenoh subscriber on the topic key)
    /// handing each sample, as the JSON of the part the port carries, to `deliver`.
    pub fn subscriber(
        &self,
        spec: TopicSpec,
        deliver: impl Fn(Vec<u8>) + Send + Sync + 'static,
    ) -> Result<Ros2Subscriber, String> {
        let (key, live, _) = self.keys(&spec, EntityKind::Subscription)?;
        let token = token(&self.session, &live, &spec.topic)?;
        let (topic, qos, ty) = (spec.topic.clone(), spec.qos, spec.ty.to_string());
        let subscriber =
            TopicSubscriber::declare(&self.session, key.clone(), &qos, move |sample| {
                let attachment = sample.attachment().map(|a| a.to_bytes().into_owned());
                let payload = sample.payload().to_bytes();
                match receive(attachment.as_deref(), &payload) {
                    Ok(()) => deliver(payload.into_owned()),
                    Err((kind, why)) => console::report_as(
                        &format!("ROS 2 topic `{}`: {kind}", spec.topic),
                        &format!(
                            "warning: a sample of the ROS 2 topic `{}` was dropped: {why}",
                            spec.topic
                        ),
                    ),
                }
            })
            .map_err(|e| format!("cannot subscribe to the ROS 2 topic `{topic}`: {e}"))?;
        let other_hashes = other_hashes(&self.session, &key, &topic, &ty)?;
        Ok(Ros2Subscriber {
            _subscriber: subscriber,
            _other_hashes: other_hashes,
            _token: token,
        })
    }
}

/// A sample of the topic's type under another RIHS01 hash (a publisher whose
/// definition of the message differs from ours) never reaches the subscription: its
/// key differs, as in rmw_zenoh. This subscriber of every hash of the topic's type
/// reports such samples (throttled, naming the topic and both hashes); ours it ignores.
fn other_hashes(
    session: &Session,
    key: &str,
    topic: &str,
    ty: &str,
) -> Result<Subscriber<()>, String> {
    let (prefix, ours) = key
        .rsplit_once('/')
        .ok_or_else(|| format!("the topic key `{key}` has no type hash"))?;
    let what = format!("cannot subscribe to the ROS 2 topic `{topic}`");
    let (ours, topic, ty) = (ours.to_string(), topic.to_string(), ty.to_string());
    session
        .declare_subscriber(format!("{prefix}/*"))
        .callback(move |sample| {
            let theirs = sample.key_expr().as_str().rsplit('/').next().unwrap_or("");
            if theirs != ours {
                console::report_as(
                    &format!("ROS 2 topic `{topic}`: hash"),
                    &format!(
                        "warning: a sample of the ROS 2 topic `{topic}` was dropped: it was \
                         sent with another type hash, {theirs} (ours: {ours}); help: the \
                         publisher's definition of `{ty}` differs from ours, give both sides \
                         the same one"
                    ),
                );
            }
        })
        .wait()
        .map_err(|e| format!("{what}: {e}"))
}

/// Whether a sample is one for the port: rmw_zenoh's attachment and the CDR header of
/// little-endian samples (the port's end decodes the rest). Else what is wrong: its
/// kind (for throttling) and the text.
fn receive(attachment: Option<&[u8]>, payload: &[u8]) -> Result<(), (&'static str, String)> {
    let attachment = attachment.ok_or((
        "attachment",
        "it has no attachment (rmw_zenoh sends one with each)".to_string(),
    ))?;
    Attachment::decode(attachment).map_err(|e| ("attachment", e.to_string()))?;
    match payload {
        [0x00, 0x01, _, _, ..] => Ok(()),
        [a, b, _, _, ..] => Err((
            "header",
            format!("its CDR header is {a:02x} {b:02x}; rmw_zenoh sends little-endian CDR (00 01)"),
        )),
        _ => Err((
            "header",
            format!("it has {} bytes, not even a CDR header", payload.len()),
        )),
    }
}

fn token(session: &Session, key: &str, what: &str) -> Result<LivelinessToken, String> {
    session
        .liveliness()
        .declare_token(key.to_string())
        .wait()
        .map_err(|e| format!("cannot announce `{what}` to ROS 2: {e}"))
}

/// A ROS 2 publisher of one topic.
pub struct Ros2Publisher {
    registry: Arc<Registry>,
    spec: TopicSpec,
    gid: [u8; 16],
    publisher: TopicPublisher,
    sequence: AtomicI64,
    _token: LivelinessToken,
}

impl Ros2Publisher {
    /// Publishes a message value (tests and tools; a running part's values arrive as
    /// CDR, [`Self::publish_cdr`]).
    pub fn publish(&self, message: &ferroc_ros2::Value) -> Result<(), String> {
        let bytes =
            cdr::encode(&self.registry, &self.spec.ty, message).map_err(|e| e.to_string())?;
        self.publish_cdr(bytes)
    }

    /// Publishes a CDR sample of the topic's message (a port's value as its end wrote
    /// it) with rmw_zenoh's attachment (sequence number from 1, the send time, the
    /// publisher's GID).
    pub fn publish_cdr(&self, bytes: impl Into<zenoh::bytes::ZBytes>) -> Result<(), String> {
        let attachment = Attachment {
            sequence_number: self.sequence.fetch_add(1, Ordering::Relaxed) + 1,
            source_timestamp: SystemTime::now()
                .duration_since(UNIX_EPOCH)
                .map_or(0, |d| d.as_nanos() as i64),
            gid: self.gid,
        };
        self.publisher
            .put(bytes, attachment.encode().to_vec())
            .map_err(|e| format!("cannot publish on `{}`: {e}", self.spec.topic))
    }

    /// The topic.
    pub fn spec(&self) -> &TopicSpec {
        &self.spec
    }
}

/// A ROS 2 subscription; dropping it ends it.
pub struct Ros2Subscriber {
    _subscriber: TopicSubscriber,
    _other_hashes: Subscriber<()>,
    _token: LivelinessToken,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sample_without_rmw_zenoh_s_attachment_or_header_is_an_error_never_a_panic() {
        let good = Attachment {
            sequence_number: 1,
            source_timestamp: 0,
            gid: [0; 16],
        }
        .encode();
        let mut sample = cdr::HEADER.to_vec();
        sample.extend(std::iter::repeat_n(0u8, 40));
        sample.extend(2.5f64.to_le_bytes());
        assert!(receive(Some(&good), &sample).is_ok());
        let short = receive(Some(&good[..20]), &sample).unwrap_err().1;
        assert!(short.contains("attachment has 20 bytes"), "{short}");
        let none = receive(None, &sample).unwrap_err().1;
        assert!(none.contains("no attachment"), "{none}");
        let big_endian = receive(Some(&good), &[0, 0, 0, 0, 1]).unwrap_err().1;
        assert!(big_endian.contains("00 00"), "{big_endian}");
        for n in 0..4 {
            assert!(receive(Some(&good), &sample[..n]).is_err());
        }
    }
}
