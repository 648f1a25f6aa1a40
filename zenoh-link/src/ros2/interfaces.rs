//! The message packages a part's ROS 2 nodes know: the shipped ones and the model's own
//! (`<ros2-interfaces>`, docs/ros2.md), whose definitions the nodes carry as text
//! (`Ros2Node::interfaces`, from the plan or a bundle's generated code).

use ferroc_ros2::{Registry, TeamFile};
use ferroc_runtime::link::ros2::Ros2Node;

/// The shipped packages with every team definition `nodes` carry. The checks (R109)
/// refused bad definitions before the run; one that still does not read (a plan written
/// by hand) is an error naming the file, line and column.
pub fn registry(nodes: &[Ros2Node]) -> Result<Registry, String> {
    let team: Vec<_> = nodes.iter().flat_map(|n| &n.interfaces).collect();
    if team.is_empty() {
        return Ok(Registry::shipped_shared().clone());
    }
    let mut seen = std::collections::BTreeSet::new();
    let files = team
        .iter()
        // Every node of a model carries the model's packages: read each file once.
        .filter(|i| seen.insert((&i.package, &i.kind, &i.name)))
        .map(|i| TeamFile {
            package: &i.package,
            kind: &i.kind,
            name: &i.name,
            text: &i.text,
            file: &i.name,
        });
    let (registry, errors) = Registry::shipped_with(files);
    match errors.first() {
        None => Ok(registry),
        Some(e) => Err(format!(
            "a ROS 2 definition of the model does not read: {e}"
        )),
    }
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
