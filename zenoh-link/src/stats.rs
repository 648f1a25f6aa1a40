//! How the values of each link a part sends travel, for `ferroc inspect` (issue 30):
//! per data link, the values sent in a shared-memory buffer, as bytes over the network
//! and dropped by a full pool; with the pool's size, the bytes it holds now and the
//! threshold. Counted where the sending path decides ([`crate::free`]), one relaxed
//! atomic add per value and link; read only when an inspector asks.

use crate::shm::{Payload, Pool};
use ferroc_runtime::link::transport::{LinkUse, PartLinks, PoolUse, TransportUse};
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicU64, Ordering};

/// How a value went: the kind of its [`Payload`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Way {
    Shared,
    Network,
    Dropped,
}

impl Way {
    pub(crate) fn of(payload: &Payload) -> Way {
        match payload {
            Payload::Shared(_) => Way::Shared,
            Payload::Network(_) => Way::Network,
            Payload::Dropped => Way::Dropped,
        }
    }
}

/// The counters of the links one part sends.
#[derive(Default)]
pub(crate) struct Stats {
    links: BTreeMap<u32, Counters>,
}

struct Counters {
    to_part: String,
    topic: String,
    shared: AtomicU64,
    network: AtomicU64,
    dropped: AtomicU64,
}

impl Stats {
    /// Counters for every data link of `links` this part sends.
    pub(crate) fn new(links: &PartLinks) -> Stats {
        let links = (links.sending.iter())
            .map(|(id, s)| {
                let counters = Counters {
                    to_part: s.to_part.clone(),
                    topic: s.topic.clone(),
                    shared: AtomicU64::new(0),
                    network: AtomicU64::new(0),
                    dropped: AtomicU64::new(0),
                };
                (*id, counters)
            })
            .collect();
        Stats { links }
    }

    /// Counts a value sent on each of `links` the way `payload` says it went.
    #[cfg(test)]
    pub(crate) fn sent(&self, links: impl IntoIterator<Item = u32>, payload: &Payload) {
        self.count(links, Way::of(payload));
    }

    /// Counts a value sent on each of `links` the way `way` (taken from its payload
    /// before the put, counted after it: the put comes first).
    pub(crate) fn count(&self, links: impl IntoIterator<Item = u32>, way: Way) {
        for link in links {
            let Some(c) = self.links.get(&link) else {
                continue;
            };
            let counter = match way {
                Way::Shared => &c.shared,
                Way::Network => &c.network,
                Way::Dropped => &c.dropped,
            };
            counter.fetch_add(1, Ordering::Relaxed);
        }
    }

    /// The figures now, with those of `pool` (a part that sends nothing has none).
    pub(crate) fn report(&self, pool: Option<&Pool>) -> TransportUse {
        let links = (self.links.iter())
            .map(|(id, c)| LinkUse {
                link: *id,
                to_part: c.to_part.clone(),
                topic: c.topic.clone(),
                shared_memory: c.shared.load(Ordering::Relaxed),
                network: c.network.load(Ordering::Relaxed),
                dropped: c.dropped.load(Ordering::Relaxed),
            })
            .collect();
        let pool = pool.and_then(|p| {
            let (size, used, threshold) = p.held()?;
            let n = |x: usize| u64::try_from(x).unwrap_or(u64::MAX);
            let usage = p.usage();
            Some(PoolUse {
                size: n(size),
                used: n(used),
                threshold: n(threshold),
                reclaimed: usage.reclaimed,
                gone_held: usage.gone_held,
            })
        });
        TransportUse { links, pool }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shm::Settings;
    use ferroc_runtime::link::transport::Sending;
    use ferroc_runtime::link::Sharing;

    fn links() -> PartLinks {
        let sending = |topic: &str| Sending {
            to_part: "station".into(),
            topic: topic.into(),
            model_type: "ferroc_std.Image".into(),
            sharing: Sharing::default(),
            reliable: false,
        };
        let mut links = PartLinks::default();
        links.sending.insert(3, sending("robot/camera/image"));
        links.sending.insert(4, sending("robot/camera/count"));
        links
    }

    #[test]
    fn each_link_counts_how_its_values_went_and_the_pool_its_bytes() {
        let pool = Pool::open(Settings {
            enabled: true,
            threshold: 4096,
            pool_size: 1 << 20,
        });
        let stats = Stats::new(&links());
        let held = pool.payload(vec![1; 100_000], false, "link");
        stats.sent([3], &held);
        stats.sent([4], &pool.payload(vec![1; 8], false, "link"));
        stats.sent([3, 4, 99], &Payload::Dropped);
        let used = stats.report(Some(&pool));
        let figures: Vec<(u32, u64, u64, u64)> = (used.links.iter())
            .map(|l| (l.link, l.shared_memory, l.network, l.dropped))
            .collect();
        assert_eq!(figures, [(3, 1, 0, 1), (4, 0, 1, 1)]);
        assert_eq!(used.links[0].topic, "robot/camera/image");
        let p = used.pool.unwrap();
        assert_eq!((p.size, p.threshold), (1 << 20, 4096));
        assert_eq!((p.reclaimed, p.gone_held), (0, 0), "no reader is gone");
        assert!(p.used >= 100_000, "the held value's buffer: {p:?}");
        drop(held);
        assert_eq!(stats.report(Some(&pool)).pool.unwrap().used, 0);
    }

    /// A full pool: a reliable link's value falls back to the network, counted there.
    #[test]
    fn a_value_a_full_pool_cannot_take_counts_as_network() {
        let pool = Pool::open(Settings {
            enabled: true,
            threshold: 4096,
            pool_size: 64 * 1024,
        });
        let stats = Stats::new(&links());
        let held = pool.payload(vec![1; 40_000], true, "link");
        stats.sent([3], &held);
        stats.sent([3], &pool.payload(vec![2; 40_000], true, "link"));
        let l = &stats.report(Some(&pool)).links[0];
        assert_eq!((l.shared_memory, l.network, l.dropped), (1, 1, 0));
    }

    #[test]
    fn without_a_pool_there_are_no_pool_figures() {
        let off = Pool::open(Settings {
            enabled: false,
            threshold: 4096,
            pool_size: 1 << 20,
        });
        let stats = Stats::new(&links());
        stats.sent([3], &off.payload(vec![1; 100_000], true, "link"));
        let used = stats.report(Some(&off));
        assert_eq!(used.pool, None);
        assert_eq!((used.links[0].shared_memory, used.links[0].network), (0, 1));
        assert_eq!(Stats::default().report(None), TransportUse::default());
    }
}
