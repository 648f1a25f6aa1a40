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
#[cfg(feature = "ros2-durability")]
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
    #[cfg(feature = "ros2-durability")]
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
        cached(session, builder, qos)
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
            #[cfg(feature = "ros2-durability")]
            TopicPublisher::TransientLocal(p) => p.put(payload).attachment(attachment).wait(),
        }
    }
}

/// A topic's Zenoh subscriber; dropping it ends it.
pub enum TopicSubscriber {
    Volatile(Subscriber<()>),
    #[cfg(feature = "ros2-durability")]
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
        with_history(builder, qos, on_sample)
    }
}

/// Why a transient-local end cannot be declared in a program built without zenoh-ext.
#[cfg(not(feature = "ros2-durability"))]
const WITHOUT_DURABILITY: &str = "transient-local durability needs ferroc-zenoh's feature \
     `ros2-durability`, which this program was built without (a bundle turns it on when a \
     part is a ROS 2 node: bundle the model again)";

/// The advanced publisher of a transient-local topic: its cache, publisher detection,
/// and (reliable, or without time stamps) sample-miss detection.
#[cfg(feature = "ros2-durability")]
fn cached(
    session: &Session,
    builder: zenoh::pubsub::PublisherBuilder<'_, 'static>,
    qos: &Qos,
) -> zenoh::Result<TopicPublisher> {
    let mut advanced = builder
        .cache(CacheConfig::default().max_samples(depth(qos)))
        .publisher_detection();
    // A best-effort cache orders by time stamp; a session without them (a part's
    // own session in a bundle, unless its configuration turns them on) numbers its
    // samples instead, which subscribers read as well.
    if qos.reliability == Reliability::Reliable || session.hlc().is_none() {
        advanced = advanced
            .sample_miss_detection(MissDetectionConfig::default().sporadic_heartbeat(HEARTBEAT));
    }
    advanced.wait().map(TopicPublisher::TransientLocal)
}

#[cfg(not(feature = "ros2-durability"))]
fn cached(
    _: &Session,
    _: zenoh::pubsub::PublisherBuilder<'_, 'static>,
    _: &Qos,
) -> zenoh::Result<TopicPublisher> {
    Err(WITHOUT_DURABILITY.into())
}

/// The advanced subscriber of a transient-local topic: history from every publisher
/// (late ones too), subscriber detection, and recovery when reliable.
#[cfg(feature = "ros2-durability")]
fn with_history(
    builder: zenoh::pubsub::SubscriberBuilder<'_, 'static, zenoh::handlers::DefaultHandler>,
    qos: &Qos,
    on_sample: impl Fn(Sample) + Send + Sync + 'static,
) -> zenoh::Result<TopicSubscriber> {
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

#[cfg(not(feature = "ros2-durability"))]
fn with_history(
    _: zenoh::pubsub::SubscriberBuilder<'_, 'static, zenoh::handlers::DefaultHandler>,
    _: &Qos,
    _: impl Fn(Sample) + Send + Sync + 'static,
) -> zenoh::Result<TopicSubscriber> {
    Err(WITHOUT_DURABILITY.into())
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
