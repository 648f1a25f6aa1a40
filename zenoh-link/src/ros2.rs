//! A part as a ROS 2 node on rmw_zenoh's wire (issue 29, docs/ros2.md): from the part's
//! own Zenoh session, the liveliness tokens by which ROS 2 discovers a node and its
//! publishers and subscriptions, samples on rmw_zenoh's topic keys with CDR payloads and
//! rmw_zenoh's attachment, and subscriptions that decode what ROS 2 nodes publish. The
//! formats are `ferroc_ros2::rmw_zenoh`'s and `ferroc_ros2::cdr`'s; values reach a
//! message through their serde JSON (`ferroc_ros2::json`), as a port's codec writes it.
//!
//! A malformed sample, one whose attachment is short, or a value that does not fit its
//! message is reported (throttled, naming the topic) and dropped: the part keeps running
//! and other topics keep flowing.

use ferroc_ros2::def::TypeName;
use ferroc_ros2::rmw_zenoh::{self, Attachment, EntityKind, NodeInfo, Qos, TopicInfo};
use ferroc_ros2::{cdr, json, Registry};
use ferroc_runtime::console;
use std::sync::atomic::{AtomicI64, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{SystemTime, UNIX_EPOCH};
use zenoh::liveliness::LivelinessToken;
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::qos::CongestionControl;
use zenoh::{Session, Wait};

pub mod network;
pub mod service;
pub mod wire;

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
        let congestion = match spec.qos.reliability {
            rmw_zenoh::Reliability::Reliable => CongestionControl::Block,
            rmw_zenoh::Reliability::BestEffort => CongestionControl::Drop,
        };
        let publisher = self
            .session
            .declare_publisher(key)
            .congestion_control(congestion)
            .wait()
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
        deliver: impl Fn(serde_json::Value) + Send + Sync + 'static,
    ) -> Result<Ros2Subscriber, String> {
        let (key, live, _) = self.keys(&spec, EntityKind::Subscription)?;
        let token = token(&self.session, &live, &spec.topic)?;
        let registry = Arc::clone(&self.registry);
        let topic = spec.topic.clone();
        let subscriber = self
            .session
            .declare_subscriber(key)
            .callback(move |sample| {
                let attachment = sample.attachment().map(|a| a.to_bytes().into_owned());
                let payload = sample.payload().to_bytes();
                match receive(&registry, &spec, attachment.as_deref(), &payload) {
                    Ok(value) => deliver(value),
                    Err(why) => console::report(&format!(
                        "warning: a sample of the ROS 2 topic `{}` was dropped: {why}",
                        spec.topic
                    )),
                }
            })
            .wait()
            .map_err(|e| format!("cannot subscribe to the ROS 2 topic `{topic}`: {e}"))?;
        Ok(Ros2Subscriber {
            _subscriber: subscriber,
            _token: token,
        })
    }
}

/// A sample as the port reads it: the attachment checked, the CDR decoded, the part the
/// port carries as JSON.
fn receive(
    registry: &Registry,
    spec: &TopicSpec,
    attachment: Option<&[u8]>,
    payload: &[u8],
) -> Result<serde_json::Value, String> {
    let attachment = attachment.ok_or("it has no attachment (rmw_zenoh sends one with each)")?;
    Attachment::decode(attachment).map_err(|e| e.to_string())?;
    let value = cdr::decode(registry, &spec.ty, payload).map_err(|e| e.to_string())?;
    json::to_json(registry, &spec.ty, spec.field.as_deref(), &value)
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
    publisher: Publisher<'static>,
    sequence: AtomicI64,
    _token: LivelinessToken,
}

impl Ros2Publisher {
    /// Publishes a port's value (its serde JSON): encoded as the message (or into its
    /// field), with rmw_zenoh's attachment (sequence number from 1, the send time, the
    /// publisher's GID).
    pub fn publish_json(&self, value: &serde_json::Value) -> Result<(), String> {
        let message = json::from_json(
            &self.registry,
            &self.spec.ty,
            self.spec.field.as_deref(),
            value,
        )?;
        self.publish(&message)
    }

    /// Publishes a message value.
    pub fn publish(&self, message: &ferroc_ros2::Value) -> Result<(), String> {
        let bytes =
            cdr::encode(&self.registry, &self.spec.ty, message).map_err(|e| e.to_string())?;
        let attachment = Attachment {
            sequence_number: self.sequence.fetch_add(1, Ordering::Relaxed) + 1,
            source_timestamp: SystemTime::now()
                .duration_since(UNIX_EPOCH)
                .map_or(0, |d| d.as_nanos() as i64),
            gid: self.gid,
        };
        self.publisher
            .put(bytes)
            .attachment(attachment.encode().to_vec())
            .wait()
            .map_err(|e| format!("cannot publish on `{}`: {e}", self.spec.topic))
    }

    /// The topic.
    pub fn spec(&self) -> &TopicSpec {
        &self.spec
    }
}

/// A ROS 2 subscription; dropping it ends it.
pub struct Ros2Subscriber {
    _subscriber: Subscriber<()>,
    _token: LivelinessToken,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn twist_spec(field: Option<&str>) -> TopicSpec {
        TopicSpec {
            topic: "/cmd_vel".into(),
            ty: TypeName::parse("geometry_msgs/msg/Twist").unwrap(),
            qos: Qos::default(),
            field: field.map(str::to_string),
        }
    }

    #[test]
    fn a_bad_sample_is_an_error_naming_what_is_wrong_never_a_panic() {
        let reg = Registry::shipped();
        let good = Attachment {
            sequence_number: 1,
            source_timestamp: 0,
            gid: [0; 16],
        }
        .encode();
        let spec = twist_spec(Some("angular.z"));
        let mut sample = cdr::HEADER.to_vec();
        sample.extend(std::iter::repeat_n(0u8, 40));
        sample.extend(2.5f64.to_le_bytes());
        assert_eq!(
            receive(&reg, &spec, Some(&good), &sample).unwrap(),
            serde_json::json!(2.5)
        );
        let short = receive(&reg, &spec, Some(&good[..20]), &sample).unwrap_err();
        assert!(short.contains("attachment has 20 bytes"), "{short}");
        let none = receive(&reg, &spec, None, &sample).unwrap_err();
        assert!(none.contains("no attachment"), "{none}");
        let truncated = receive(&reg, &spec, Some(&good), &sample[..30]).unwrap_err();
        assert!(!truncated.is_empty());
        for n in 0..sample.len() {
            let _ = receive(&reg, &spec, Some(&good), &sample[..n]);
        }
    }
}
