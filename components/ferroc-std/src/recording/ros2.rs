//! Recorded ports that are ROS 2 topics (issue 29): an output the model publishes as a
//! topic (`<ros2><publish>`) gets, besides its exact and display channels, a channel on
//! the ROS 2 topic (`/cmd_vel`) with message encoding `cdr` and a schema of encoding
//! `ros2msg` named `package/msg/Name`, holding the message's definition with its
//! dependencies (MCAP's `ros2` profile), so ROS 2 tools, Foxglove and `rosbags` read it
//! as the ROS data the topic carries. Its metadata names the ferroc port as the other
//! channels' does (`ferroc.port`, `ferroc.part`, `ferroc.type`, `ferroc.unit`), the form
//! `ros2`, and the one field the port carries (`ferroc.ros2.field`) if not all of it.
//!
//! The CDR comes from the program's ROS 2 wire (`ferroc_runtime::link::ros2_wire`),
//! which only a program with ROS 2 nodes has (its network lends it): in any other
//! program no port is ROS-typed and recordings are as they were.

use super::read::ChannelSummary;
use ferroc_runtime::link::ros2_wire::{self, Ros2Wire};
use std::sync::Arc;

/// Message encoding of ROS 2 channels.
pub const ROS2_ENCODING: &str = "cdr";
/// Schema encoding of ROS 2 channels.
pub const ROS2_SCHEMA_ENCODING: &str = "ros2msg";
/// Metadata key of a ROS 2 channel whose port carries one field of the message.
pub const META_ROS2_FIELD: &str = "ferroc.ros2.field";
/// The form (`ferroc.form`) of ROS 2 channels.
pub const ROS2_FORM: &str = "ros2";

/// How a recorded port is written on its ROS 2 topic.
#[derive(Clone)]
pub struct Ros2Form {
    /// The fully qualified topic (`/cmd_vel`): the channel's topic.
    pub topic: String,
    /// The message type, `package/msg/Name`: the schema's name.
    pub message: String,
    /// The field of the message the port carries (`data`), if not all of it.
    pub field: Option<String>,
    /// The `ros2msg` schema text.
    pub schema: String,
    wire: Arc<dyn Ros2Wire>,
}

impl std::fmt::Debug for Ros2Form {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Ros2Form")
            .field("topic", &self.topic)
            .field("message", &self.message)
            .field("field", &self.field)
            .finish_non_exhaustive()
    }
}

impl Ros2Form {
    /// The ROS 2 form of the output at `port` (`module/path/port`), if the program
    /// publishes it as a topic; an error if its message has no schema here.
    pub fn of_port(port: &str) -> Result<Option<Ros2Form>, String> {
        let (Some(wire), Some(topic)) = (ros2_wire::wire(), ros2_wire::published(port)) else {
            return Ok(None);
        };
        let schema = wire.schema(&topic.message).map_err(|why| {
            format!(
                "the ROS 2 topic `{}` of `{port}` is not recorded as ROS data: {why}",
                topic.topic
            )
        })?;
        Ok(Some(Ros2Form {
            topic: topic.topic,
            message: topic.message,
            field: topic.field,
            schema,
            wire,
        }))
    }

    /// The CDR sample of a value of the port (its serde JSON).
    pub fn encode(&self, json: &[u8]) -> Result<Vec<u8>, String> {
        self.wire.encode(&self.message, self.field.as_deref(), json)
    }
}

/// A ROS 2 channel of a recording, as a player replays it: its messages become a
/// port's values (serde JSON) through the program's ROS 2 wire.
pub struct Ros2Channel {
    message: String,
    field: Option<String>,
    wire: Arc<dyn Ros2Wire>,
}

impl Ros2Channel {
    /// The decoder of `channel` (a ROS 2 channel: [`ChannelSummary::is_ros2`]); an
    /// error when this program has no ROS 2 wire.
    pub fn of(channel: &ChannelSummary) -> Result<Ros2Channel, String> {
        let wire = ros2_wire::wire().ok_or_else(|| {
            format!(
                "the channel `{}` holds ROS 2 messages ({}), which only a program with a ROS 2 \
                 node decodes",
                channel.topic, channel.schema_name
            )
        })?;
        Ok(Ros2Channel {
            message: channel.schema_name.clone(),
            field: channel.metadata.get(META_ROS2_FIELD).cloned(),
            wire,
        })
    }

    /// The port's value (serde JSON) of one recorded message.
    pub fn decode(&self, cdr: &[u8]) -> Result<Vec<u8>, String> {
        self.wire.decode(&self.message, self.field.as_deref(), cdr)
    }
}
