//! The message packages a part's ROS 2 nodes know: the shipped ones and the model's own
//! (`<ros2-interfaces>`, docs/ros2.md), whose definitions the nodes carry as text
//! (`Ros2Node::interfaces`, from the plan or a bundle's generated code).

use ferroc_ros2::Registry;
use ferroc_runtime::link::ros2::{team_registry, Ros2Node};

/// The shipped packages with every team definition `nodes` carry (the runtime's
/// [`team_registry`]: the network hashes and keys with the same definitions the
/// ports' ends encode with).
pub fn registry(nodes: &[Ros2Node]) -> Result<Registry, String> {
    team_registry(nodes.iter().flat_map(|n| &n.interfaces))
}

#[cfg(test)]
mod tests {
    use super::*;
    use ferroc_ros2::def::TypeName;
    use ferroc_runtime::link::ros2::Ros2Interface;

    fn node(definitions: &[(&str, &str)]) -> Ros2Node {
        Ros2Node {
            interfaces: definitions
                .iter()
                .map(|(name, text)| Ros2Interface {
                    package: "robot_msgs".into(),
                    kind: "msg".into(),
                    name: name.to_string(),
                    text: text.to_string(),
                })
                .collect(),
            ..Ros2Node::default()
        }
    }

    #[test]
    fn a_team_s_types_join_the_shipped_ones_once_however_many_nodes_carry_them() {
        let wheel = node(&[("Wheel", "float64 speed\ngeometry_msgs/Vector3 axis\n")]);
        let registry = registry(&[wheel.clone(), wheel]).unwrap();
        assert!(registry
            .message(&TypeName::new("robot_msgs", "msg", "Wheel"))
            .is_some());
        assert!(registry
            .message(&TypeName::new("geometry_msgs", "msg", "Twist"))
            .is_some());
    }

    #[test]
    fn a_definition_that_does_not_read_is_an_error_not_a_panic() {
        let bad = node(&[("Bad", "float64[<=x] ranges\n")]);
        let why = registry(&[bad]).unwrap_err();
        assert!(why.contains("Bad:1:"), "{why}");
        let shipped = Ros2Node {
            interfaces: vec![Ros2Interface {
                package: "std_msgs".into(),
                kind: "msg".into(),
                name: "Mine".into(),
                text: "bool data\n".into(),
            }],
            ..Ros2Node::default()
        };
        assert!(registry(&[shipped]).unwrap_err().contains("std_msgs"));
    }
}
