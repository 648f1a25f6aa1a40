//! The Zenoh QoS of a link running freely (the table in docs/zenoh.md).

use ferroc_runtime::link::transport::Sending;
use zenoh::qos::CongestionControl;

/// The Zenoh QoS of a link (the table in docs/zenoh.md).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Qos {
    /// *block* for links that must not drop values, *drop* for the others.
    pub congestion: CongestionControl,
    /// Sent at once, without waiting to be batched: values of the built-in scalar types
    /// (a few bytes each), whose worth is being current.
    pub express: bool,
}

impl Qos {
    /// The QoS of the link `sending`.
    pub fn of(sending: &Sending) -> Qos {
        const SMALL: &[&str] = &[
            "f64",
            "f32",
            "i8",
            "i16",
            "i32",
            "i64",
            "u8",
            "u16",
            "u32",
            "u64",
            "bool",
            "Stimulation",
            "Inhibition",
            "Activity",
            "TargetRating",
        ];
        Qos {
            congestion: if sending.reliable {
                CongestionControl::Block
            } else {
                CongestionControl::Drop
            },
            express: SMALL.contains(&sending.model_type.as_str()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ferroc_runtime::link::Sharing;

    fn sending(model_type: &str, reliable: bool) -> Sending {
        Sending {
            to_part: "station".into(),
            topic: "robot/x/out".into(),
            model_type: model_type.into(),
            sharing: Sharing::default(),
            reliable,
        }
    }

    #[test]
    fn reliable_links_block_others_drop_and_small_values_go_express() {
        let victims = Qos::of(&sending("rescue.VictimList", true));
        assert_eq!(victims.congestion, CongestionControl::Block);
        assert!(!victims.express, "a list is not small");
        let pose = Qos::of(&sending("f64", false));
        assert_eq!(pose.congestion, CongestionControl::Drop);
        assert!(pose.express);
        assert!(!Qos::of(&sending("Vec<f64>", false)).express);
    }
}
