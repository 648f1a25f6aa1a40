//! rmw_zenoh's wire formats (ros2/rmw_zenoh, `docs/design.md` and
//! `rmw_zenoh_cpp/src/detail/`): the key expression of a topic or service, the
//! attachment every sample and request carries, and the liveliness tokens by which
//! nodes, publishers, subscriptions, service servers and clients are discovered.
use std::fmt;

use crate::def::TypeName;

/// `<domain>/<fully qualified name without leading or trailing slash>/<DDS type name>/<RIHS01 hash>`
/// (liveliness_utils.cpp, `TopicInfo::TopicInfo`; design.md "Topic and Service name
/// mapping to Zenoh key expressions"). Services use the same form with their service type.
pub fn topic_key(domain: u32, name: &str, ty: &TypeName, hash: &str) -> String {
    format!("{domain}/{}/{}/{hash}", strip_slashes(name), ty.dds_name())
}

/// The name without one leading and one trailing `/` (liveliness_utils.cpp, `strip_slashes`).
fn strip_slashes(name: &str) -> &str {
    let name = name.strip_prefix('/').unwrap_or(name);
    name.strip_suffix('/').unwrap_or(name)
}

/// `/` replaced by `%`, as liveliness tokens carry names (liveliness_utils.cpp, `mangle_name`).
pub fn mangle(name: &str) -> String {
    name.replace('/', "%")
}

/// `%` back to `/` (liveliness_utils.cpp, `demangle_name`).
pub fn demangle(name: &str) -> String {
    name.replace('%', "/")
}

/// Reliability (rmw's `rmw_qos_reliability_policy_e` numbering).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reliability {
    Reliable = 1,
    BestEffort = 2,
}

/// Durability (rmw's `rmw_qos_durability_policy_e` numbering).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Durability {
    TransientLocal = 1,
    Volatile = 2,
}

/// History (rmw's `rmw_qos_history_policy_e`: keep last = 1, keep all = 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum History {
    KeepLast(u32),
    KeepAll,
}

/// The QoS a ferroc port declares. Deadline, lifespan and liveliness are ROS 2's
/// defaults (infinite, automatic), which rmw_zenoh writes as empty components.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Qos {
    pub reliability: Reliability,
    pub durability: Durability,
    pub history: History,
}

/// rmw_zenoh's default depth (qos.cpp, `RMW_ZENOH_DEFAULT_HISTORY_DEPTH`), used when the
/// depth is 0 or history is keep-all.
pub const DEFAULT_DEPTH: u32 = 42;

impl Default for Qos {
    /// rclcpp's default profile: reliable, volatile, keep last 10.
    fn default() -> Self {
        Qos {
            reliability: Reliability::Reliable,
            durability: Durability::Volatile,
            history: History::KeepLast(10),
        }
    }
}

impl Qos {
    /// The compact QoS component of a liveliness token (liveliness_utils.cpp,
    /// `qos_to_keyexpr`): `reliability:durability:history,depth:deadline_s,deadline_ns:
    /// lifespan_s,lifespan_ns:liveliness,lease_s,lease_ns`, each left empty where it
    /// equals rmw_zenoh's default (qos.cpp: reliable, volatile, keep last, depth 42,
    /// infinite durations, automatic liveliness).
    pub fn keyexpr(&self) -> String {
        let reliability = match self.reliability {
            Reliability::Reliable => String::new(),
            other => (other as u8).to_string(),
        };
        let durability = match self.durability {
            Durability::Volatile => String::new(),
            other => (other as u8).to_string(),
        };
        let (history, depth) = match self.history {
            History::KeepLast(d) => (String::new(), d),
            History::KeepAll => ("2".to_string(), DEFAULT_DEPTH),
        };
        let depth = if depth == 0 || depth == DEFAULT_DEPTH {
            String::new()
        } else {
            depth.to_string()
        };
        format!("{reliability}:{durability}:{history},{depth}:,:,:,,")
    }
}

/// What a liveliness token announces.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EntityKind {
    Node,
    Publisher,
    Subscription,
    ServiceServer,
    ServiceClient,
}

impl EntityKind {
    /// `NN`, `MP`, `MS`, `SS`, `SC` (liveliness_utils.cpp, `entity_to_str`).
    pub fn code(self) -> &'static str {
        match self {
            EntityKind::Node => "NN",
            EntityKind::Publisher => "MP",
            EntityKind::Subscription => "MS",
            EntityKind::ServiceServer => "SS",
            EntityKind::ServiceClient => "SC",
        }
    }
}

/// The node an entity belongs to. Names are ROS 2's: the namespace and enclave are
/// absolute (`/` when none), the name is the node's base name.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NodeInfo {
    pub domain: u32,
    /// The Zenoh session id as Zenoh prints it (lower-case hex).
    pub zid: String,
    /// The node's id within its session (a counter).
    pub node_id: u64,
    pub enclave: String,
    pub namespace: String,
    pub name: String,
}

/// The topic or service a publisher, subscription, server or client is on.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TopicInfo {
    /// The fully qualified name (`/chatter`).
    pub name: String,
    pub ty: TypeName,
    /// `RIHS01_…`.
    pub hash: String,
    pub qos: Qos,
}

/// The liveliness token's key expression (liveliness_utils.cpp, `Entity::Entity`):
/// `@ros2_lv/<domain>/<zid>/<node id>/<entity id>/<kind>/<enclave>/<namespace>/<node>`
/// and, for all but nodes, `/<topic>/<DDS type>/<hash>/<qos>`, names mangled. A node's
/// entity id is its node id.
pub fn liveliness_key(
    node: &NodeInfo,
    kind: EntityKind,
    entity_id: u64,
    topic: Option<&TopicInfo>,
) -> String {
    let id = if kind == EntityKind::Node {
        node.node_id
    } else {
        entity_id
    };
    let mut key = format!(
        "@ros2_lv/{}/{}/{}/{id}/{}/{}/{}/{}",
        node.domain,
        node.zid,
        node.node_id,
        kind.code(),
        mangle(&node.enclave),
        mangle(&node.namespace),
        mangle(&node.name)
    );
    if let Some(t) = topic {
        key.push_str(&format!(
            "/{}/{}/{}/{}",
            mangle(&t.name),
            mangle(&t.ty.dds_name()),
            mangle(&t.hash),
            t.qos.keyexpr()
        ));
    }
    key
}

/// The entity's GID as rmw_zenoh derives it (liveliness_utils.cpp, `Entity::Entity`):
/// the XXH3 128-bit hash of its liveliness key expression, the low 64 bits then the high
/// 64 bits, each little endian. It goes into every attachment the entity sends.
pub fn gid_of(liveliness_key: &str) -> [u8; 16] {
    xxhash_rust::xxh3::xxh3_128(liveliness_key.as_bytes()).to_le_bytes()
}

/// What every published sample, request and reply carries besides its payload
/// (attachment_helpers.cpp, `AttachmentData`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Attachment {
    /// Per publisher (or client), starting at 1.
    pub sequence_number: i64,
    /// Nanoseconds since the UNIX epoch when the sample was sent.
    pub source_timestamp: i64,
    /// The sender's GID.
    pub gid: [u8; 16],
}

/// The attachment is 33 bytes: `sequence_number` (i64 LE), `source_timestamp` (i64 LE),
/// the GID as a zenoh-ext sequence: its length 16 as a LEB128 varint (`0x10`), then its
/// 16 bytes (attachment_helpers.cpp, `serialize_to_zbytes`, with zenoh-ext's serializer).
pub const ATTACHMENT_LEN: usize = 33;

impl Attachment {
    pub fn encode(&self) -> [u8; ATTACHMENT_LEN] {
        let mut out = [0u8; ATTACHMENT_LEN];
        out[..8].copy_from_slice(&self.sequence_number.to_le_bytes());
        out[8..16].copy_from_slice(&self.source_timestamp.to_le_bytes());
        out[16] = 16;
        out[17..].copy_from_slice(&self.gid);
        out
    }

    /// Reads an attachment; a short, long or otherwise malformed one is an error.
    pub fn decode(bytes: &[u8]) -> Result<Self, AttachmentError> {
        if bytes.len() != ATTACHMENT_LEN {
            return Err(AttachmentError(format!(
                "the attachment has {} bytes; rmw_zenoh's has {ATTACHMENT_LEN} (sequence number, \
                 timestamp, 16-byte GID)",
                bytes.len()
            )));
        }
        if bytes[16] != 16 {
            return Err(AttachmentError(format!(
                "the attachment's GID length is {}; rmw_zenoh's GID has 16 bytes",
                bytes[16]
            )));
        }
        let i64_at = |at: usize| i64::from_le_bytes(bytes[at..at + 8].try_into().expect("8 bytes"));
        Ok(Attachment {
            sequence_number: i64_at(0),
            source_timestamp: i64_at(8),
            gid: bytes[17..].try_into().expect("16 bytes"),
        })
    }
}

/// A malformed attachment.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AttachmentError(pub String);

impl fmt::Display for AttachmentError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for AttachmentError {}
