//! Who connects to whom. A plain part (not a ROS 2 node) opens TCP connections only to
//! the parts it is linked with — data and parameter links either way, calls either way
//! (the sets lockstep waits on too) — and of two linked parts only the one whose name
//! sorts later connects; the other only listens. So a star of 15 consumers around a
//! camera has 15 connections, not a mesh of 15 × 16 / 2, and two parts never connect to
//! each other at the same moment. Zenoh's gossip stays on (a foreign peer connected to
//! one part still hears of that part's neighbours), but parts do not autoconnect to
//! what gossip tells them (`scouting/gossip/autoconnect: []`).
//!
//! A part that is a ROS 2 node keeps the session rmw_zenoh's nodes expect: every part as
//! an endpoint and Zenoh's gossip autoconnect. A `--zenoh-config` file that sets
//! `connect/endpoints` or `scouting/gossip/autoconnect` keeps its own (docs/zenoh.md).

use super::{endpoint, set, sets};
use ferroc_runtime::link::transport::{Addresses, PartLinks};
use std::collections::BTreeSet;

/// The gossip key parts set to `[]`: no connection to a peer that gossip reports.
pub const AUTOCONNECT: &str = "scouting/gossip/autoconnect";

/// The parts `addresses.part` opens a connection to, with their addresses: those it is
/// linked with whose name sorts before its own (the later of two connects).
pub fn connects_to<'a>(addresses: &'a Addresses, links: &PartLinks) -> Vec<(&'a str, &'a str)> {
    let me = addresses.part.as_str();
    let linked: BTreeSet<&str> = links
        .sends_to()
        .union(&links.receives_from())
        .copied()
        .collect();
    (addresses.peers.iter())
        .filter(|(part, _)| part.as_str() < me && linked.contains(part.as_str()))
        .map(|(part, address)| (part.as_str(), address.as_str()))
        .collect()
}

/// Narrows `config` (which connects to every part) to the parts `links` names, as the
/// module says, for every key the file's tree `given` does not set.
pub(super) fn narrow(
    config: &mut zenoh::Config,
    given: &serde_json::Value,
    addresses: &Addresses,
    links: &PartLinks,
) -> Result<(), String> {
    if !links.ros2.is_empty() {
        return Ok(());
    }
    if !sets(given, "connect/endpoints") {
        let mut peers = Vec::new();
        for (part, address) in connects_to(addresses, links) {
            let flag = format!("--peer {part}=HOST:PORT");
            peers.push(format!("\"{}\"", endpoint(address, &flag)?));
        }
        set(
            config,
            "connect/endpoints",
            &format!("[{}]", peers.join(",")),
        )?;
    }
    if !sets(given, AUTOCONNECT) {
        set(config, AUTOCONNECT, "[]")?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::{ModelShm, PartConfig};
    use super::*;
    use ferroc_runtime::link::transport::{RemoteCall, Sending};
    use ferroc_runtime::link::Sharing;
    use std::time::Duration;

    /// A camera and three viewers, at ports 47800 + position.
    fn star(part: &str) -> Addresses {
        let names = ["camera", "viewer-1", "viewer-2", "viewer-3"];
        Addresses {
            part: part.into(),
            listen: "127.0.0.1:0".into(),
            peers: (names.iter().enumerate())
                .map(|(i, n)| (n.to_string(), format!("127.0.0.1:{}", 47800 + i)))
                .collect(),
        }
    }

    fn sending(to: &str) -> Sending {
        Sending {
            to_part: to.into(),
            topic: "camera/cam/image".into(),
            model_type: "ferroc_std.Image".into(),
            sharing: Sharing::OnChange {
                min_interval: Duration::ZERO,
            },
            reliable: false,
        }
    }

    /// The camera sends one link to each viewer.
    fn camera_links() -> PartLinks {
        PartLinks {
            part: "camera".into(),
            sending: (1..=3)
                .map(|i| (i, sending(&format!("viewer-{i}"))))
                .collect(),
            ..PartLinks::default()
        }
    }

    fn viewer_links(i: u32) -> PartLinks {
        PartLinks {
            part: format!("viewer-{i}"),
            receiving: [(i, "camera".to_string())].into(),
            ..PartLinks::default()
        }
    }

    fn endpoints(part: &str, links: &PartLinks, file: Option<&std::path::Path>) -> String {
        let addresses = star(part);
        let config = PartConfig::new(&addresses, file, ModelShm::default()).unwrap();
        let c = config.for_links(&addresses, links).unwrap();
        c.get_json("connect/endpoints").unwrap()
    }

    #[test]
    fn in_a_star_each_viewer_connects_to_the_camera_only_and_the_camera_to_nobody() {
        assert_eq!(endpoints("camera", &camera_links(), None), "[]");
        for i in 1..=3 {
            let e = endpoints(&format!("viewer-{i}"), &viewer_links(i), None);
            assert_eq!(e, "[\"tcp/127.0.0.1:47800\"]", "viewer-{i}");
        }
        let addresses = star("viewer-2");
        let c = PartConfig::new(&addresses, None, ModelShm::default()).unwrap();
        let c = c.for_links(&addresses, &viewer_links(2)).unwrap();
        assert_eq!(c.get_json(AUTOCONNECT).unwrap(), "[]", "no gossip mesh");
        // Without the links (what ROS 2 sessions and the bare benchmark take), every
        // other part stays an endpoint.
        let every = PartConfig::new(&addresses, None, ModelShm::default()).unwrap();
        let all = every.every_part().get_json("connect/endpoints").unwrap();
        assert_eq!(all.matches("tcp/").count(), 3, "{all}");
    }

    #[test]
    fn parts_that_call_each_other_stay_connected_by_the_later_name() {
        // viewer-3 serves a call of viewer-1 and sends a link back: they are linked both
        // ways, and only viewer-3 (the later name) connects, to viewer-1 and the camera.
        let call = RemoteCall {
            client_part: "viewer-1".into(),
            server_part: "viewer-3".into(),
            service: "viewer-3/ops/zoom".into(),
        };
        let mut one = viewer_links(1);
        one.calls_out.insert(0, call.clone());
        one.receiving.insert(7, "viewer-3".into());
        let mut three = viewer_links(3);
        three.calls_in.insert(0, call);
        three.sending.insert(7, sending("viewer-1"));
        assert_eq!(
            endpoints("viewer-1", &one, None),
            "[\"tcp/127.0.0.1:47800\"]"
        );
        let e = endpoints("viewer-3", &three, None);
        assert_eq!(
            e, "[\"tcp/127.0.0.1:47800\",\"tcp/127.0.0.1:47801\"]",
            "the camera and viewer-1, not viewer-2"
        );
        // A part linked with nobody connects to nobody.
        assert_eq!(endpoints("viewer-2", &PartLinks::default(), None), "[]");
    }

    #[test]
    fn a_ros2_node_part_and_a_file_that_sets_the_keys_keep_their_own() {
        let mut node = viewer_links(1);
        node.ros2.push(Default::default());
        let e = endpoints("viewer-1", &node, None);
        assert_eq!(
            e.matches("tcp/").count(),
            3,
            "every part, as rmw_zenoh: {e}"
        );
        let addresses = star("viewer-1");
        let c = PartConfig::new(&addresses, None, ModelShm::default()).unwrap();
        let c = c.for_links(&addresses, &node).unwrap();
        let gossip = c.get_json(AUTOCONNECT).unwrap();
        assert_ne!(gossip, "[]", "Zenoh's own gossip autoconnect");
        let dir = std::env::temp_dir().join(format!("ferroc-zenoh-connect-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("mesh.json5");
        std::fs::write(
            &file,
            "{ connect: { endpoints: [\"tcp/10.0.0.9:7447\"] }, \
               scouting: { gossip: { autoconnect: { peer: [\"router\", \"peer\"] } } } }",
        )
        .unwrap();
        let e = endpoints("viewer-1", &viewer_links(1), Some(&file));
        assert_eq!(e, "[\"tcp/10.0.0.9:7447\"]");
        let c = PartConfig::new(&addresses, Some(&file), ModelShm::default()).unwrap();
        let c = c.for_links(&addresses, &viewer_links(1)).unwrap();
        assert!(c.get_json(AUTOCONNECT).unwrap().contains("peer"));
    }
}
