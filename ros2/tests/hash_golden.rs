//! RIHS01 hashes against values rmw_zenoh's design document states (ros2/rmw_zenoh,
//! docs/design.md, section "Topic and Service name mapping to Zenoh key expressions",
//! at commit 99a6a2bd10b949052f4f12c5854825dc005e95a5): they were produced by rosidl,
//! so agreeing with them checks our type description and hashing byte for byte.
use ferroc_ros2::def::TypeName;
use ferroc_ros2::{hash, Registry};

#[test]
fn std_msgs_string_hash_is_the_one_in_rmw_zenoh_design_doc() {
    let registry = Registry::shipped();
    let ty = TypeName::parse("std_msgs/msg/String").unwrap();
    // design.md: `0/chatter/std_msgs::msg::dds_::String_/RIHS01_df668c74…6b1a18`
    assert_eq!(
        hash::rihs01(&registry, &ty).unwrap(),
        "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18"
    );
}

#[test]
fn a_service_hash_is_the_one_in_rmw_zenoh_design_doc() {
    // example_interfaces/srv/AddTwoInts as ROS 2 ships it (three fields); not shipped by
    // us, so added here as a team would add its own package.
    let mut registry = Registry::shipped();
    registry
        .add_text(
            "example_interfaces",
            "srv",
            "AddTwoInts",
            "int64 a\nint64 b\n---\nint64 sum\n",
            "AddTwoInts.srv",
        )
        .unwrap();
    assert!(registry.check().is_empty());
    let ty = TypeName::parse("example_interfaces/srv/AddTwoInts").unwrap();
    // design.md: `2/add_two_ints/example_interfaces::srv::dds_::AddTwoInts_/RIHS01_e118de6b…c81a`
    assert_eq!(
        hash::rihs01(&registry, &ty).unwrap(),
        "RIHS01_e118de6bf5eeb66a2491b5bda11202e7b68f198d6f67922cf30364858239c81a"
    );
}

#[test]
fn default_values_and_constants_do_not_change_the_hash() {
    // REP-2016: the hash covers the fields' names and types, not defaults or constants.
    let hash_of = |text: &str| {
        let mut r = Registry::new();
        r.add_text("demo_pkg", "msg", "Limits", text, "Limits.msg")
            .unwrap();
        hash::rihs01(&r, &TypeName::parse("demo_pkg/msg/Limits").unwrap()).unwrap()
    };
    let plain = hash_of("float64 max_speed\nstring<=8 name\n");
    assert_eq!(
        plain,
        hash_of("uint8 KIND=3\nfloat64 max_speed 1.5\nstring<=8 name \"fast\"\n")
    );
    assert_ne!(plain, hash_of("float64 max_speed\nstring<=9 name\n"));
    assert_ne!(plain, hash_of("float32 max_speed\nstring<=8 name\n"));
}
