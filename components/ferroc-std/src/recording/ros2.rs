//! Recorded ports that are ROS 2 topics (issue 29): a port the model publishes as a
//! topic (`<ros2><publish>`) or subscribes from one (`<subscribe>`) gets, besides its
//! exact and display channels, a channel on the ROS 2 topic (`/cmd_vel`) with message
//! encoding `cdr` and a schema of encoding `ros2msg` named `package/msg/Name`, holding
//! the message's definition with its dependencies (MCAP's `ros2` profile), so ROS 2
//! tools, Foxglove and `rosbags` read it as the ROS data the topic carries. Its metadata
//! names the ferroc port as the other channels' does (`ferroc.port`, `ferroc.part`,
//! `ferroc.type`, `ferroc.unit`), the form `ros2`, and the one field the port carries
//! (`ferroc.ros2.field`) if not all of it.
//!
//! Each value is written as CDR straight from the port's value by the code the wire
//! uses (`Codec::ros2_encode` with the end's `serde_cdr::Shape`, in the definitions of
//! the port's node: shipped and the model's own packages), so every value is recorded,
//! non-finite floats too. Which ports are topics the program's builder tells
//! (`ferroc_runtime::link::ros2_wire`); in a program without ROS 2 nodes none is.
//!
//! One ROS 2 channel per topic: several recorded ports may be ends of one topic (two
//! inputs subscribing it, a part publishing what another subscribes), and a ROS 2 tool
//! expects one stream per topic. The channel is written by one of them, the first of:
//! a port publishing the topic, then a port subscribing all of the message (no
//! `field=`, or the one field of a wrapper such as `std_msgs/msg/Float64`), then one
//! subscribing one field of it; among equals the end the model declares first. The
//! others keep their exact and display channels.
//!
//! A player replays a ROS 2 channel ([`Ros2Channel`]) with the definitions its schema
//! holds (`mcap_schema::registry_of`): ours, or those of a bag another tool wrote, a
//! team's own types included. Any program decodes them.

use super::read::ChannelSummary;
use ferroc_ros2::def::TypeName;
use ferroc_ros2::mcap_schema;
use ferroc_ros2::serde_cdr::{self, Shape};
use ferroc_ros2::Registry;
use ferroc_runtime::link::ros2::topic_shape;
use ferroc_runtime::link::ros2_wire::{self, Ros2End};
use ferroc_runtime::module::{Codec, DynIn, DynOut};
use std::collections::BTreeSet;
use std::sync::{Mutex, PoisonError};

/// Message encoding of ROS 2 channels.
pub const ROS2_ENCODING: &str = "cdr";
/// Schema encoding of ROS 2 channels.
pub const ROS2_SCHEMA_ENCODING: &str = "ros2msg";
/// Metadata key of a ROS 2 channel whose port carries one field of the message.
pub const META_ROS2_FIELD: &str = "ferroc.ros2.field";
/// The form (`ferroc.form`) of ROS 2 channels.
pub const ROS2_FORM: &str = "ros2";

/// The ports recorded in this process (by recorders and loggers), among which each
/// topic's channel finds its writer.
static RECORDED: Mutex<BTreeSet<String>> = Mutex::new(BTreeSet::new());

/// Tells that `ports` (`module/path/port`) are recorded: called when a recording module
/// is created, before any value is written.
pub fn add_recorded<'a>(ports: impl IntoIterator<Item = &'a str>) {
    let mut recorded = RECORDED.lock().unwrap_or_else(PoisonError::into_inner);
    recorded.extend(ports.into_iter().map(str::to_owned));
}

/// How a recorded port is written on its ROS 2 topic.
#[derive(Clone, Debug)]
pub struct Ros2Form {
    /// The fully qualified topic (`/cmd_vel`): the channel's topic.
    pub topic: String,
    /// The message type, `package/msg/Name`: the schema's name.
    pub message: String,
    /// The field of the message the port carries (`data`), if not all of it.
    pub field: Option<String>,
    /// The `ros2msg` schema text.
    pub schema: String,
    /// Whether the port publishes the topic (else it subscribes it).
    pub publish: bool,
    shape: Shape<'static>,
    /// The topic's `frame-id=` (a published end's; `""` if none).
    frame_id: String,
}

impl Ros2Form {
    /// The ROS 2 form of the port `port` (`module/path/port`), if it is published or
    /// subscribed as a topic and writes that topic's channel (see the module docs); an
    /// error if its message has no definition here.
    pub fn of_port(port: &str) -> Result<Option<Ros2Form>, String> {
        let Some(end) = ros2_wire::end_of(port) else {
            return Ok(None);
        };
        if writer(&end.topic.topic).as_deref() != Some(port) {
            return Ok(None);
        }
        let not_recorded = |why: String| {
            format!(
                "the ROS 2 topic `{}` of `{port}` is not recorded as ROS data: {why}",
                end.topic.topic
            )
        };
        let ty = TypeName::parse(&end.topic.message)
            .filter(|t| t.kind == "msg")
            .ok_or_else(|| not_recorded(format!("`{}` is not a message", end.topic.message)))?;
        let schema = mcap_schema::schema_text(end.registry, &ty).map_err(not_recorded)?;
        let shape = topic_shape(&end.topic, end.registry).map_err(not_recorded)?;
        Ok(Some(Ros2Form {
            topic: end.topic.topic,
            message: end.topic.message,
            field: end.topic.field,
            schema,
            publish: end.topic.publish,
            shape,
            frame_id: end.topic.frame_id,
        }))
    }

    /// Replaces `cdr` with the latest value of `input` (of the value type whose codec
    /// is `codec`) as a CDR sample of the topic's message.
    pub fn encode(&self, codec: &Codec, input: &DynIn, cdr: &mut Vec<u8>) -> Result<(), String> {
        codec.ros2_encode_framed(input, &self.shape, &self.frame_id, cdr)
    }
}

/// The port (`module/path/port`) whose values the channel of `topic` holds: the first
/// recorded end by the order of the module docs.
fn writer(topic: &str) -> Option<String> {
    let recorded = RECORDED.lock().unwrap_or_else(PoisonError::into_inner);
    let path = |e: &Ros2End| format!("{}/{}", e.topic.port.0, e.topic.port.1);
    ros2_wire::ends_on(topic)
        .into_iter()
        .filter(|e| recorded.contains(&path(e)))
        .min_by_key(|e| (!e.topic.publish, !whole(e), e.topic.id))
        .map(|e| path(&e))
}

/// Whether the end carries all of its message: no `field=`, or the one field of a
/// wrapper (`data` of `std_msgs/msg/Float64`).
fn whole(e: &Ros2End) -> bool {
    let Some(field) = &e.topic.field else {
        return true;
    };
    let message = TypeName::parse(&e.topic.message).and_then(|t| e.registry.message(&t));
    message.is_some_and(|m| m.fields.len() == 1 && m.fields[0].name == *field)
}

/// The definitions a channel is read in: its schema's, or (an empty schema) the
/// program's: those of its ROS 2 nodes that define the message, else the shipped ones.
enum Definitions {
    Program,
    Schema(Registry),
}

/// A ROS 2 channel of a recording, as a player replays it: its messages become a
/// port's values, read straight into it (`Codec::ros2_decode`).
pub struct Ros2Channel {
    definitions: Definitions,
    message: TypeName,
    field: Option<String>,
}

impl Ros2Channel {
    /// The reader of `channel` (a ROS 2 channel: [`ChannelSummary::is_ros2`]), with the
    /// definitions its schema holds; an error naming the channel if they do not read. A
    /// channel whose schema is empty (a tool that found no definition) is read with the
    /// program's definitions ([`Self::shape`]), which may be known only once the
    /// program's nodes are declared: then it is not checked here.
    pub fn of(channel: &ChannelSummary) -> Result<Ros2Channel, String> {
        let bad = |why: String| {
            format!(
                "the ROS 2 channel `{}` ({}) cannot be read: {why}",
                channel.topic, channel.schema_name
            )
        };
        let message = TypeName::parse(&channel.schema_name)
            .filter(|t| t.kind == "msg")
            .ok_or_else(|| bad("its schema names no message type (package/msg/Name)".into()))?;
        let text = String::from_utf8_lossy(&channel.schema_data);
        let definitions = if text.trim().is_empty() {
            Definitions::Program
        } else {
            Definitions::Schema(mcap_schema::registry_of(&message, &text).map_err(bad)?)
        };
        let read = Ros2Channel {
            definitions,
            message,
            field: channel.metadata.get(META_ROS2_FIELD).cloned(),
        };
        if let Definitions::Schema(_) = read.definitions {
            read.shape().map_err(bad)?;
        }
        Ok(read)
    }

    /// Whether the messages are read with the program's definitions (the schema is
    /// empty), not with the file's.
    pub fn of_program(&self) -> bool {
        matches!(self.definitions, Definitions::Program)
    }

    /// What the channel's messages are: the message, or the field the port carries.
    pub fn shape(&self) -> Result<Shape<'_>, String> {
        let registry = match &self.definitions {
            Definitions::Program => (ros2_wire::definitions().into_iter())
                .find(|r| r.message(&self.message).is_some())
                .unwrap_or(Registry::shipped_shared()),
            Definitions::Schema(r) => r,
        };
        Shape::new(registry, &self.message, self.field.as_deref()).map_err(|why| {
            match &self.definitions {
                Definitions::Program => format!(
                    "{why} (the recording holds no definition of it, nor do this program's \
                     ROS 2 nodes)"
                ),
                Definitions::Schema(_) => why,
            }
        })
    }

    /// Whether `cdr` is a sample of the message (every length and the whole sample
    /// read), before any port's type is asked.
    pub fn check(shape: &Shape<'_>, cdr: &[u8]) -> Result<(), String> {
        serde_cdr::from_cdr::<serde::de::IgnoredAny>(shape, cdr)
            .map(|_| ())
            .map_err(|e| e.to_string())
    }

    /// Reads `cdr` into the value of `out` (of the value type whose codec is `codec`)
    /// and publishes it.
    pub fn publish(
        codec: &Codec,
        out: &DynOut,
        shape: &Shape<'_>,
        cdr: &[u8],
    ) -> Result<(), String> {
        codec.ros2_decode(out, shape, cdr)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn channel(schema_name: &str, schema: &str, field: Option<&str>) -> ChannelSummary {
        ChannelSummary {
            id: 1,
            topic: "/motion".into(),
            message_encoding: ROS2_ENCODING.into(),
            schema_name: schema_name.into(),
            schema_encoding: ROS2_SCHEMA_ENCODING.into(),
            schema_data: schema.as_bytes().to_vec(),
            metadata: (field.iter())
                .map(|f| (META_ROS2_FIELD.to_owned(), (*f).to_owned()))
                .collect(),
            count: 0,
            first: None,
            last: None,
        }
    }

    #[test]
    fn a_channel_is_read_with_its_schema_s_team_types_and_a_bad_sample_is_refused() {
        let text = "team_msgs/Speed linear\nfloat64 turn\n=====\nMSG: team_msgs/Speed\n\
                    float64 x\n";
        let read = Ros2Channel::of(&channel("team_msgs/msg/Motion", text, None)).unwrap();
        let shape = read.shape().unwrap();
        let mut cdr = vec![0, 1, 0, 0];
        cdr.extend(1.5f64.to_le_bytes());
        cdr.extend(f64::NAN.to_le_bytes());
        assert_eq!(Ros2Channel::check(&shape, &cdr), Ok(()));
        assert!(Ros2Channel::check(&shape, &cdr[..10]).is_err(), "short");
        let longer = [cdr.as_slice(), &[0; 9]].concat();
        assert!(Ros2Channel::check(&shape, &longer).is_err(), "bytes left");
        // One field of it, as `ferroc.ros2.field` says.
        let field = Ros2Channel::of(&channel("team_msgs/msg/Motion", text, Some("linear.x")));
        assert!(field.is_ok());
    }

    #[test]
    fn a_schema_that_does_not_read_is_an_error_naming_the_channel_and_an_empty_one_is_shipped() {
        let broken = Ros2Channel::of(&channel("team_msgs/msg/Motion", "float65 x\n", None));
        let why = broken.err().unwrap();
        assert!(why.contains("`/motion`"), "{why}");
        assert!(why.contains(":1:"), "the line: {why}");
        let missing = Ros2Channel::of(&channel(
            "team_msgs/msg/Motion",
            "team_msgs/Speed s\n",
            None,
        ));
        assert!(missing.is_err(), "a nested type the schema lacks");
        let no_field = Ros2Channel::of(&channel(
            "std_msgs/msg/Float64",
            "float64 data\n",
            Some("x"),
        ));
        assert!(no_field.err().unwrap().contains("no field `x`"));
        // An empty schema: the shipped definitions.
        let shipped = Ros2Channel::of(&channel("geometry_msgs/msg/Vector3", "", None)).unwrap();
        assert!(shipped.of_program());
        let mut cdr = vec![0, 1, 0, 0];
        cdr.extend([0u8; 24]);
        assert_eq!(Ros2Channel::check(&shipped.shape().unwrap(), &cdr), Ok(()));
        let unknown = Ros2Channel::of(&channel("nobody_msgs/msg/Nothing", "", None)).unwrap();
        let why = unknown.shape().err().unwrap();
        assert!(why.contains("nor do this program's ROS 2 nodes"), "{why}");
    }

    #[test]
    fn an_empty_schema_is_read_with_the_team_definitions_of_the_program_s_nodes() {
        use ferroc_runtime::link::ros2::{Ros2Interface, Ros2Node};
        let team = channel("h29r_team_msgs/msg/Pair", "", None);
        let read = Ros2Channel::of(&team).unwrap();
        assert!(read.shape().is_err(), "no node defines it yet");
        ferroc_runtime::link::ros2_wire::add_node(&Ros2Node {
            part: "robot".into(),
            domain: 0,
            namespace: "/".into(),
            name: "robot".into(),
            topics: vec![],
            services: vec![],
            clients: vec![],
            interfaces: vec![Ros2Interface {
                package: "h29r_team_msgs".into(),
                kind: "msg".into(),
                name: "Pair".into(),
                text: "int32 a\nint32 b\n".into(),
            }],
        })
        .unwrap();
        let shape = read.shape().unwrap();
        let cdr = [
            [0, 1, 0, 0].as_slice(),
            &7i32.to_le_bytes(),
            &9i32.to_le_bytes(),
        ]
        .concat();
        assert_eq!(Ros2Channel::check(&shape, &cdr), Ok(()));
    }
}
