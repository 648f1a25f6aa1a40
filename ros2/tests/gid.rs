//! The GID rmw_zenoh derives from a liveliness key (XXH3-128, liveliness_utils.cpp
//! `Entity::Entity`), against the reference xxHash library (PyPI `xxhash`, the C
//! implementation's binding) on every length class XXH3 treats differently.
use std::process::Command;

use ferroc_ros2::rmw_zenoh::gid_of;

#[test]
fn gid_is_the_reference_xxh3_128_of_the_key() {
    let Some(python) = ferroc_testkit::python(&["xxhash"]) else {
        return;
    };
    let token = "@ros2_lv/2/8b20917502ee955ac4476e0266340d5c/0/10/MP/%/%/talker/%chatter/std_msgs::msg::dds_::String_/RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18/::,7:,:,:,,";
    // XXH3 has separate paths for 0, 1-3, 4-8, 9-16, 17-128, 129-240 and longer inputs.
    let mut keys: Vec<String> = [
        0usize, 1, 3, 4, 8, 9, 16, 17, 100, 128, 129, 200, 240, 241, 300, 1500,
    ]
    .iter()
    .map(|n| token.chars().cycle().take(*n).collect())
    .collect();
    keys.push(token.to_string());
    let script = "import sys, xxhash\nfor k in sys.argv[1:]:\n    print(xxhash.xxh3_128_intdigest(k.encode()).to_bytes(16, 'little').hex())";
    let out = Command::new(python)
        .arg("-c")
        .arg(script)
        .args(&keys)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let theirs: Vec<String> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(String::from)
        .collect();
    assert_eq!(theirs.len(), keys.len());
    for (key, want) in keys.iter().zip(&theirs) {
        let ours: String = gid_of(key).iter().map(|b| format!("{b:02x}")).collect();
        assert_eq!(&ours, want, "GID of a {}-byte key", key.len());
    }
}
