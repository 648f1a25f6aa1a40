//! Transient-local durability on rmw_zenoh's wire (docs/ros2.md, "Transient local").
//!
//! A ROS 2 publisher whose QoS is `transient-local` keeps its last `depth` samples for
//! subscribers that join later; a transient-local subscription asks for them when it
//! starts and whenever a new publisher of its topic appears. rmw_zenoh (Kilted 0.6 and
//! Rolling; `rmw_publisher_data.cpp`, `rmw_subscription_data.cpp`) does this with
//! zenoh-ext's advanced publisher and subscriber, and so does this module:
//!
//! - the publisher: a cache of the last `depth` samples (keep-all: rmw_zenoh's default
//!   depth), answering queries on `<topic key>/@adv/pub/<zid>/…`; publisher detection
//!   (zenoh-ext's liveliness token, by which subscribers find late publishers); when
//!   reliable, sample-miss detection with a sporadic heartbeat every 500 ms, so a
//!   reliable subscriber can fetch what it missed;
//! - the subscription: history (the last `depth` samples of each publisher, from
//!   publishers already there and from late ones), subscriber detection, and when
//!   reliable, recovery of missed samples on the heartbeat.
//!
//! A volatile end is a plain Zenoh publisher or subscriber, as rmw_zenoh's is (its
//! advanced publisher without options sends exactly what a plain one does).
//!
//! A cache without sequence numbers (best effort) orders its samples by their time
//! stamps, which the session must give: [`session_settings`] turns time stamping on,
//! as rmw_zenoh's default session configuration does.

use ferroc_ros2::rmw_zenoh::{self, Durability, History, Qos, Reliability};
use std::time::Duration;
use zenoh::bytes::ZBytes;
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::qos::CongestionControl;
use zenoh::sample::Sample;
use zenoh::{Config, Session, Wait};
use zenoh_ext::{
    AdvancedPublisher, AdvancedPublisherBuilderExt, AdvancedSubscriber,
    AdvancedSubscriberBuilderExt, CacheConfig, HistoryConfig, MissDetectionConfig, RecoveryConfig,
};

/// rmw_zenoh's period of the heartbeat of a reliable transient-local publisher
/// (`SAMPLE_MISS_DETECTION_HEARTBEAT_PERIOD`, 500 ms, sporadic: only after a put).
pub const HEARTBEAT: Duration = Duration::from_millis(500);

/// The number of samples a transient-local end keeps or asks for: the QoS depth, or
/// rmw_zenoh's default depth for keep-all and for a depth of 0.
pub fn depth(qos: &Qos) -> usize {
    match qos.history {
        History::KeepLast(n) if n > 0 => n as usize,
        _ => rmw_zenoh::DEFAULT_DEPTH as usize,
    }
}

/// Whether `qos` asks for the advanced (caching, history-fetching) ends.
pub fn is_transient_local(qos: &Qos) -> bool {
    qos.durability == Durability::TransientLocal
}

/// What a ROS 2 session needs for transient-local ends: time stamps on the samples it
/// sends (`timestamping/enabled`), as rmw_zenoh's default configuration sets it.
pub fn session_settings(config: &mut Config) -> Result<(), String> {
    config
        .insert_json5("timestamping/enabled", "true")
        .map_err(|e| format!("cannot turn on Zenoh's time stamps: {e}"))
}

/// A topic's Zenoh publisher: plain when volatile, with a cache when transient-local.
pub enum TopicPublisher {
    Volatile(Publisher<'static>),
    TransientLocal(AdvancedPublisher<'static>),
}

impl TopicPublisher {
    /// Declares the publisher of `key` with `qos` (congestion: reliable blocks, best
    /// effort drops).
    pub fn declare(session: &Session, key: String, qos: &Qos) -> zenoh::Result<TopicPublisher> {
        let congestion = match qos.reliability {
            Reliability::Reliable => CongestionControl::Block,
            Reliability::BestEffort => CongestionControl::Drop,
        };
        let builder = session
            .declare_publisher(key)
            .congestion_control(congestion);
        if !is_transient_local(qos) {
            return builder.wait().map(TopicPublisher::Volatile);
        }
        let mut advanced = builder
            .cache(CacheConfig::default().max_samples(depth(qos)))
            .publisher_detection();
        // A best-effort cache orders by time stamp; a session without them (a part's
        // own session in a bundle, unless its configuration turns them on) numbers its
        // samples instead, which subscribers read as well.
        if qos.reliability == Reliability::Reliable || session.hlc().is_none() {
            advanced = advanced.sample_miss_detection(
                MissDetectionConfig::default().sporadic_heartbeat(HEARTBEAT),
            );
        }
        advanced.wait().map(TopicPublisher::TransientLocal)
    }

    /// Sends one sample with its attachment (and keeps it, when transient-local).
    pub fn put(
        &self,
        payload: impl Into<ZBytes>,
        attachment: impl Into<ZBytes>,
    ) -> zenoh::Result<()> {
        let attachment: ZBytes = attachment.into();
        match self {
            TopicPublisher::Volatile(p) => p.put(payload).attachment(attachment).wait(),
            TopicPublisher::TransientLocal(p) => p.put(payload).attachment(attachment).wait(),
        }
    }
}

/// A topic's Zenoh subscriber; dropping it ends it.
pub enum TopicSubscriber {
    Volatile(Subscriber<()>),
    TransientLocal(AdvancedSubscriber<()>),
}

impl TopicSubscriber {
    /// Declares the subscriber of `key` with `qos`, handing each sample (live, or from a
    /// publisher's cache) to `on_sample`.
    pub fn declare(
        session: &Session,
        key: String,
        qos: &Qos,
        on_sample: impl Fn(Sample) + Send + Sync + 'static,
    ) -> zenoh::Result<TopicSubscriber> {
        let builder = session.declare_subscriber(key);
        if !is_transient_local(qos) {
            return builder
                .callback(on_sample)
                .wait()
                .map(TopicSubscriber::Volatile);
        }
        let history = HistoryConfig::default()
            .detect_late_publishers()
            .max_samples(depth(qos));
        let mut advanced = builder.history(history).subscriber_detection();
        if qos.reliability == Reliability::Reliable {
            advanced = advanced.recovery(RecoveryConfig::default().heartbeat());
        }
        advanced
            .callback(on_sample)
            .wait()
            .map(TopicSubscriber::TransientLocal)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn qos(durability: Durability, history: History) -> Qos {
        Qos {
            reliability: Reliability::Reliable,
            durability,
            history,
        }
    }

    #[test]
    fn the_cache_keeps_the_depth_or_rmw_zenoh_s_default() {
        let keep = |h| depth(&qos(Durability::TransientLocal, h));
        assert_eq!(keep(History::KeepLast(5)), 5);
        assert_eq!(keep(History::KeepLast(0)), 42);
        assert_eq!(keep(History::KeepAll), 42);
    }

    #[test]
    fn only_transient_local_ends_are_advanced() {
        assert!(is_transient_local(&qos(
            Durability::TransientLocal,
            History::KeepLast(1)
        )));
        assert!(!is_transient_local(&Qos::default()));
    }

    #[test]
    fn the_session_settings_turn_time_stamps_on() {
        let mut config = Config::default();
        session_settings(&mut config).unwrap();
        let on = config.get_json("timestamping/enabled").unwrap();
        assert!(on.contains("true"), "{on}");
    }
}
