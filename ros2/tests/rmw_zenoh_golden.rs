//! rmw_zenoh's wire formats, byte for byte against what rmw_zenoh itself writes.
//!
//! Sources (public repository ros2/rmw_zenoh, as stored in the reference index):
//! - docs/design.md @ 99a6a2bd10b949052f4f12c5854825dc005e95a5, section "Topic and
//!   Service name mapping to Zenoh key expressions" (the three key examples) and section
//!   "Graph Cache" (the five liveliness token examples from demo_nodes_cpp).
//! - rmw_zenoh_cpp/src/detail/liveliness_utils.cpp @ 3411fdec149fe0c932f24d4d79ef908eb81d7482:
//!   `TopicInfo::TopicInfo` (topic key), `Entity::Entity` (token layout), `qos_to_keyexpr`,
//!   `mangle_name`, the constants `ADMIN_SPACE = "@ros2_lv"`, `NODE_STR = "NN"`,
//!   `PUB_STR = "MP"`, `SUB_STR = "MS"`, `SRV_STR = "SS"`, `CLI_STR = "SC"`.
//! - rmw_zenoh_cpp/src/detail/qos.cpp @ 7efeee2b9009b816a4bd4a3148af3cca40f753d5: the
//!   defaults an empty QoS component stands for (reliable, volatile, keep last, depth 42).
//! - rmw_zenoh_cpp/src/detail/attachment_helpers.cpp @ 534747dca92adf15e1b1b975123037ca278db5ba:
//!   `AttachmentData::serialize_to_zbytes` (sequence number, source timestamp, GID through
//!   zenoh-ext's serializer: i64 little endian, and `std::array<uint8_t, 16>` as a
//!   sequence, its length a LEB128 varint).
//!
//! The RIHS01 hashes in these strings are computed by this crate, not copied: that they
//! equal design.md's checks the hashing too.
use ferroc_ros2::def::TypeName;
use ferroc_ros2::rmw_zenoh::{
    demangle, liveliness_key, mangle, topic_key, Attachment, Durability, EntityKind, History,
    NodeInfo, Qos, Reliability, TopicInfo,
};
use ferroc_ros2::{hash, Registry};

fn registry() -> Registry {
    let mut r = Registry::shipped();
    // example_interfaces/srv/AddTwoInts, which design.md's service examples use.
    r.add_text(
        "example_interfaces",
        "srv",
        "AddTwoInts",
        "int64 a\nint64 b\n---\nint64 sum\n",
        "AddTwoInts.srv",
    )
    .unwrap();
    r
}

fn string_type(r: &Registry) -> (TypeName, String) {
    let t = TypeName::parse("std_msgs/msg/String").unwrap();
    let h = hash::rihs01(r, &t).unwrap();
    (t, h)
}

fn add_two_ints(r: &Registry) -> (TypeName, String) {
    let t = TypeName::parse("example_interfaces/srv/AddTwoInts").unwrap();
    let h = hash::rihs01(r, &t).unwrap();
    (t, h)
}

fn node(domain: u32, zid: &str, name: &str) -> NodeInfo {
    NodeInfo {
        domain,
        zid: zid.into(),
        node_id: 0,
        enclave: "/".into(),
        namespace: "/".into(),
        name: name.into(),
    }
}

fn depth(d: u32) -> Qos {
    Qos {
        history: History::KeepLast(d),
        ..Qos::default()
    }
}

#[test]
fn topic_and_service_keys_are_design_md_examples() {
    let r = registry();
    let (string, h) = string_type(&r);
    assert_eq!(
        topic_key(0, "/chatter", &string, &h),
        "0/chatter/std_msgs::msg::dds_::String_/RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18"
    );
    assert_eq!(
        topic_key(0, "/robot1/chatter", &string, &h),
        "0/robot1/chatter/std_msgs::msg::dds_::String_/RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18"
    );
    let (srv, h) = add_two_ints(&r);
    assert_eq!(
        topic_key(2, "/add_two_ints", &srv, &h),
        "2/add_two_ints/example_interfaces::srv::dds_::AddTwoInts_/RIHS01_e118de6bf5eeb66a2491b5bda11202e7b68f198d6f67922cf30364858239c81a"
    );
    assert_eq!(
        TypeName::parse("geometry_msgs/msg/Twist")
            .unwrap()
            .dds_name(),
        "geometry_msgs::msg::dds_::Twist_"
    );
}

#[test]
fn liveliness_tokens_of_each_kind_are_design_md_examples() {
    let r = registry();
    let (string, sh) = string_type(&r);
    let (srv, vh) = add_two_ints(&r);
    let listener = node(2, "aac3178e146ba6f1fc6e6a4085e77f21", "listener");
    assert_eq!(
        liveliness_key(&listener, EntityKind::Node, 0, None),
        "@ros2_lv/2/aac3178e146ba6f1fc6e6a4085e77f21/0/0/NN/%/%/listener"
    );
    let chatter = |qos| TopicInfo {
        name: "/chatter".into(),
        ty: string.clone(),
        hash: sh.clone(),
        qos,
    };
    assert_eq!(
        liveliness_key(&listener, EntityKind::Subscription, 10, Some(&chatter(depth(10)))),
        "@ros2_lv/2/aac3178e146ba6f1fc6e6a4085e77f21/0/10/MS/%/%/listener/%chatter/std_msgs::msg::dds_::String_/RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18/::,10:,:,:,,"
    );
    let talker = node(2, "8b20917502ee955ac4476e0266340d5c", "talker");
    assert_eq!(
        liveliness_key(&talker, EntityKind::Publisher, 10, Some(&chatter(depth(7)))),
        "@ros2_lv/2/8b20917502ee955ac4476e0266340d5c/0/10/MP/%/%/talker/%chatter/std_msgs::msg::dds_::String_/RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18/::,7:,:,:,,"
    );
    let service = TopicInfo {
        name: "/add_two_ints".into(),
        ty: srv,
        hash: vh,
        qos: depth(10),
    };
    let server = node(2, "f9980ee0495eaafb3e38f0d19e2eae12", "add_two_ints_server");
    assert_eq!(
        liveliness_key(&server, EntityKind::ServiceServer, 10, Some(&service)),
        "@ros2_lv/2/f9980ee0495eaafb3e38f0d19e2eae12/0/10/SS/%/%/add_two_ints_server/%add_two_ints/example_interfaces::srv::dds_::AddTwoInts_/RIHS01_e118de6bf5eeb66a2491b5bda11202e7b68f198d6f67922cf30364858239c81a/::,10:,:,:,,"
    );
    let client = node(2, "e1dc8d1b45ae8717fce78689cc655685", "add_two_ints_client");
    assert_eq!(
        liveliness_key(&client, EntityKind::ServiceClient, 10, Some(&service)),
        "@ros2_lv/2/e1dc8d1b45ae8717fce78689cc655685/0/10/SC/%/%/add_two_ints_client/%add_two_ints/example_interfaces::srv::dds_::AddTwoInts_/RIHS01_e118de6bf5eeb66a2491b5bda11202e7b68f198d6f67922cf30364858239c81a/::,10:,:,:,,"
    );
}

#[test]
fn namespaces_and_qos_are_encoded_as_qos_to_keyexpr_does() {
    // mangle_name: every `/` becomes `%`.
    assert_eq!(mangle("/robot1/nav"), "%robot1%nav");
    assert_eq!(demangle("%robot1%nav"), "/robot1/nav");
    let mut n = node(0, "1234abcd", "driver");
    n.namespace = "/robot1".into();
    n.node_id = 3;
    assert_eq!(
        liveliness_key(&n, EntityKind::Node, 99, None),
        "@ros2_lv/0/1234abcd/3/3/NN/%/%robot1/driver"
    );
    // Only components that differ from qos.cpp's defaults are written, as numbers of
    // rmw's enums (best effort 2, transient local 1, keep all 2).
    assert_eq!(depth(42).keyexpr(), "::,:,:,:,,");
    let sensor = Qos {
        reliability: Reliability::BestEffort,
        durability: Durability::Volatile,
        history: History::KeepLast(5),
    };
    assert_eq!(sensor.keyexpr(), "2::,5:,:,:,,");
    let latched = Qos {
        reliability: Reliability::Reliable,
        durability: Durability::TransientLocal,
        history: History::KeepLast(1),
    };
    assert_eq!(latched.keyexpr(), ":1:,1:,:,:,,");
    let all = Qos {
        reliability: Reliability::Reliable,
        durability: Durability::Volatile,
        history: History::KeepAll,
    };
    assert_eq!(all.keyexpr(), "::2,:,:,:,,");
}

#[test]
fn attachment_is_33_bytes_as_serialize_to_zbytes_writes_it() {
    let gid: [u8; 16] = std::array::from_fn(|i| 0xa0 + i as u8);
    let a = Attachment {
        sequence_number: 1,
        source_timestamp: 1_700_000_000_123_456_789,
        gid,
    };
    let bytes = a.encode();
    let mut expected = vec![1, 0, 0, 0, 0, 0, 0, 0];
    expected.extend(1_700_000_000_123_456_789i64.to_le_bytes());
    expected.push(0x10); // LEB128 16: the GID's length as a zenoh-ext sequence
    expected.extend(gid);
    assert_eq!(bytes.to_vec(), expected);
    assert_eq!(
        bytes[8..16],
        [0x15, 0xcd, 0x85, 0x3d, 0xfe, 0x9c, 0x97, 0x17],
        "1700000000123456789 = 0x17979CFE3D85CD15, little endian"
    );
    assert_eq!(Attachment::decode(&bytes).unwrap(), a);
    let e = Attachment::decode(&bytes[..20]).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("the attachment has 20 bytes; rmw_zenoh's has 33"),
        "{e}"
    );
    let mut bad = bytes;
    bad[16] = 8;
    assert!(Attachment::decode(&bad)
        .unwrap_err()
        .to_string()
        .contains("GID length is 8"));
}
