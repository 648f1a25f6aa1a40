//! The network's figures of the links a part sends ([`ferroc_link::transport::TransportUse`])
//! as the inspector's [`TransportView`](super::view::TransportView) parts.

use super::view::{LinkTransportView, PoolView};
use ferroc_link::transport::{LinkUse, PoolUse};

/// A link's figures, with the way its values went in words.
pub(super) fn link_view(l: LinkUse) -> LinkTransportView {
    let by = match (l.shared_memory > 0, l.network > 0) {
        (true, false) => "shared memory",
        (false, true) => "network",
        (true, true) => "shared memory and network",
        (false, false) => "nothing sent yet",
    };
    LinkTransportView {
        output: l.topic,
        to_part: l.to_part,
        by: by.into(),
        shared_memory: l.shared_memory,
        network: l.network,
        dropped: l.dropped,
    }
}

pub(super) fn pool_view(p: PoolUse) -> PoolView {
    PoolView {
        size: p.size,
        used: p.used,
        threshold: p.threshold,
        reclaimed: p.reclaimed,
        gone_held: p.gone_held,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_link_says_how_its_values_went() {
        let link = |shared_memory, network| LinkUse {
            link: 1,
            to_part: "station".into(),
            topic: "robot/cam/image".into(),
            shared_memory,
            network,
            dropped: 0,
        };
        let by = |s, n| link_view(link(s, n)).by;
        assert_eq!(by(3, 0), "shared memory");
        assert_eq!(by(0, 3), "network");
        assert_eq!(by(2, 1), "shared memory and network");
        assert_eq!(by(0, 0), "nothing sent yet");
        assert_eq!(link_view(link(1, 0)).output, "robot/cam/image");
    }
}
