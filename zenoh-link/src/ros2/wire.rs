//! The ROS 2 wire lent to the rest of the program (`ferroc_runtime::link::ros2_wire`):
//! a port's value (its serde JSON) as its topic's CDR and back, and a message's
//! `ros2msg` schema text, so that recordings write ROS-typed ports as ROS 2 tools read
//! them and a player replays such channels (docs/recording-and-utilities.md).
//!
//! [`install`] is called where a program's ROS 2 network is made and where its nodes
//! open (with the registry they use); a program without ROS 2 never calls it.

use ferroc_ros2::def::TypeName;
use ferroc_ros2::{cdr, json, mcap_schema, Registry};
use ferroc_runtime::link::ros2::Ros2Topic;
use ferroc_runtime::link::ros2_wire::{self, Ros2Wire};
use std::sync::Arc;

/// The wire of the definitions in `registry`.
struct Wire {
    registry: Arc<Registry>,
}

impl Wire {
    fn message(message: &str) -> Result<TypeName, String> {
        TypeName::parse(message)
            .filter(|t| t.kind == "msg")
            .ok_or_else(|| format!("`{message}` is not a ROS 2 message type (package/msg/Name)"))
    }
}

impl Ros2Wire for Wire {
    fn schema(&self, message: &str) -> Result<String, String> {
        mcap_schema::schema_text(&self.registry, &Self::message(message)?)
    }

    /// The one place a recorded value becomes CDR: the JSON path the ROS 2 publishers
    /// take today (`json::from_json`, `cdr::encode`).
    fn encode(&self, message: &str, field: Option<&str>, value: &[u8]) -> Result<Vec<u8>, String> {
        let ty = Self::message(message)?;
        let value = serde_json::from_slice(value).map_err(|e| e.to_string())?;
        let message = json::from_json(&self.registry, &ty, field, &value)?;
        cdr::encode(&self.registry, &ty, &message).map_err(|e| e.to_string())
    }

    fn decode(&self, message: &str, field: Option<&str>, bytes: &[u8]) -> Result<Vec<u8>, String> {
        let ty = Self::message(message)?;
        let message = cdr::decode(&self.registry, &ty, bytes).map_err(|e| e.to_string())?;
        let value = json::to_json(&self.registry, &ty, field, &message)?;
        serde_json::to_vec(&value).map_err(|e| e.to_string())
    }
}

/// Lends the wire of `registry`'s definitions to the program and tells it `topics`, the
/// topic ends of the nodes being opened (none when only the network is made).
pub fn install<'a>(registry: Arc<Registry>, topics: impl IntoIterator<Item = &'a Ros2Topic>) {
    ros2_wire::install(Arc::new(Wire { registry }));
    ros2_wire::add_topics(topics);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_value_crosses_to_cdr_and_back_and_a_bad_sample_is_an_error() {
        let wire = Wire {
            registry: Arc::new(Registry::shipped()),
        };
        let cdr = wire
            .encode("std_msgs/msg/Float64", Some("data"), b"2.5")
            .unwrap();
        assert_eq!(
            cdr,
            [0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 4, 64],
            "header, then 2.5"
        );
        let back = wire
            .decode("std_msgs/msg/Float64", Some("data"), &cdr)
            .unwrap();
        assert_eq!(back, b"2.5");
        assert!(wire
            .decode("std_msgs/msg/Float64", None, &cdr[..6])
            .is_err());
        assert!(wire.schema("std_msgs/srv/Nothing").is_err());
        assert_eq!(
            wire.schema("std_msgs/msg/Float64").unwrap(),
            "float64 data\n"
        );
    }
}
