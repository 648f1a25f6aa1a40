//! Lockstep: the whole application (or this part of it) run in simulated time on one
//! thread, the same way every time.
//!
//! Model time jumps from one release instant to the next: the instants `k·period` of
//! every periodic container of the application (all parts, so that separate programs
//! agree on them). At each instant the driver
//!
//! 1. delivers the values links carried since the previous instant (sorted by link),
//! 2. runs the periodic containers due now, in declaration order, and every continuous
//!    container once,
//! 3. runs each data-triggered container that was woken, in declaration order, until
//!    none is left (each at most once per instant: a container woken again waits for
//!    the next instant),
//! 4. sends what the links produced; a part's values reach other parts at the next
//!    instant, in one process or over the network alike.
//!
//! Modules reading [`Timestamp::now`](ferroc_module::Timestamp::now) get model time.
//! Because links deliver one instant later, running all parts in one process gives
//! each part exactly what it gets when the parts run as separate programs.

use super::running::Shared;
use super::start::Links;
use super::{BuildError, RunningApp};
use ferroc_exec::{ThreadContainer, ThreadOptions, Trigger};
use ferroc_link::transport::Connection;
use ferroc_link::{Frame, Hub, Inbox, Route};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// Lockstep settings.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Lockstep {
    /// The periods of every periodic container of the whole application. Empty: the
    /// periods of the containers built here (enough when every part is here).
    pub periods: Vec<Duration>,
    /// Stop after this much model time (`--for` in lockstep): no instant after it runs.
    pub until: Option<Duration>,
}

impl Lockstep {
    pub(super) fn start(
        self,
        containers: Vec<(ThreadContainer, ThreadOptions)>,
        links: Links,
        shared: Shared,
        limit: Option<u64>,
    ) -> Result<RunningApp, BuildError> {
        let containers: Vec<ThreadContainer> = containers.into_iter().map(|(c, _)| c).collect();
        let mut periods = self.periods;
        if periods.is_empty() {
            periods = containers
                .iter()
                .filter_map(|c| match c.trigger() {
                    Trigger::Periodic(p) => Some(*p),
                    _ => None,
                })
                .collect();
        }
        links.hub.set_route(Route::Collect(Mutex::default()));
        let network = links.open(true).map_err(BuildError::Connect)?;
        let stats = containers.iter().map(|c| c.stats()).collect();
        let mut driver = Driver {
            containers,
            timeline: Timeline::new(&periods, limit, self.until),
            hub: links.hub,
            inbox: links.inbox,
            network,
        };
        RunningApp::start_driver(stats, shared, move |stop| driver.run(stop))
    }
}

/// The release instants of the application, in nanoseconds of model time.
struct Timeline {
    periods: Vec<u128>,
    limit: Option<u64>,
    until: Option<u128>,
}

impl Timeline {
    fn new(periods: &[Duration], limit: Option<u64>, until: Option<Duration>) -> Self {
        let mut periods: Vec<u128> = periods
            .iter()
            .map(|p| p.as_nanos())
            .filter(|p| *p > 0)
            .collect();
        if periods.is_empty() {
            // Only continuous and data-triggered containers: one instant per millisecond.
            periods.push(1_000_000);
        }
        periods.sort_unstable();
        periods.dedup();
        Timeline {
            periods,
            limit,
            until: until.map(|u| u.as_nanos()),
        }
    }

    /// The first instant after `after` (or the start).
    fn next(&self, after: Option<u128>) -> Option<u128> {
        self.next_within_limit(after)
            .filter(|t| self.until.is_none_or(|u| *t <= u))
    }

    /// The first instant after `after` that the cycle limit allows: `--cycles N` is N
    /// cycles of the application's fastest container, so the instants before N times
    /// the shortest period (see [`crate::builder::cycles_of`]).
    fn next_within_limit(&self, after: Option<u128>) -> Option<u128> {
        let end = self
            .limit
            .map(|l| u128::from(l).saturating_mul(self.periods[0]));
        self.periods
            .iter()
            .map(|&p| after.map_or(0, |a| a / p + 1) * p)
            .min()
            .filter(|t| end.is_none_or(|end| *t < end))
    }
}

struct Driver {
    containers: Vec<ThreadContainer>,
    timeline: Timeline,
    hub: Arc<Hub>,
    inbox: Arc<Inbox>,
    network: Option<Box<dyn Connection>>,
}

impl Driver {
    /// Runs to the end; what ended it, if not the cycle limit, or why it failed (a
    /// part it is linked to is gone).
    fn run(&mut self, stop: &AtomicBool) -> Result<Option<&'static str>, String> {
        let ended = self.run_instants(stop);
        ferroc_ports::time::set_model_time(None);
        if let Some(network) = &self.network {
            network.close();
        }
        ended
    }

    fn run_instants(&mut self, stop: &AtomicBool) -> Result<Option<&'static str>, String> {
        let mut pending: Vec<Frame> = Vec::new();
        let mut previous: Option<u128> = None;
        // An error of the network while this part was asked to stop is the stop.
        let failed = |why: String| {
            if stop.load(Ordering::Relaxed) {
                Ok(None)
            } else {
                Err(format!("lockstep stopped: {why}"))
            }
        };
        while let Some(now) = self.timeline.next(previous) {
            if stop.load(Ordering::Relaxed) {
                return Ok(None);
            }
            let nanos = u64::try_from(now).unwrap_or(u64::MAX);
            ferroc_ports::time::set_model_time(Some(Duration::from_nanos(nanos)));
            let mut frames = std::mem::take(&mut pending);
            if let (Some(before), Some(network)) = (previous, &self.network) {
                match network.wait_instant(u64::try_from(before).unwrap_or(u64::MAX), stop) {
                    Ok(arrived) => frames.extend(arrived),
                    Err(why) => return failed(why),
                }
            }
            frames.sort_by_key(|f| f.link);
            for frame in &frames {
                self.inbox.deliver(frame);
            }
            self.run_instant(now);
            let (local, remote) = Hub::split_local(self.hub.take_collected(), &self.inbox);
            pending = local;
            if let Some(network) = &self.network {
                if let Err(why) = network.end_instant(nanos, remote, stop) {
                    return failed(why);
                }
            }
            previous = Some(now);
        }
        let more = self.timeline.next_within_limit(previous).is_some();
        Ok((more && self.timeline.next(previous).is_none()).then_some("model time is up"))
    }

    /// Steps 2 and 3 of the module documentation (the timeline holds the cycle limit).
    fn run_instant(&mut self, now: u128) {
        for c in self.containers.iter_mut() {
            let due = match c.trigger() {
                Trigger::Periodic(p) => now % p.as_nanos().max(1) == 0,
                Trigger::Continuous => true,
                Trigger::Data(_) => false,
            };
            if due {
                c.run_cycle();
            }
        }
        let mut ran = vec![false; self.containers.len()];
        loop {
            let mut any = false;
            for (i, c) in self.containers.iter_mut().enumerate() {
                let Trigger::Data(wakeup) = c.trigger() else {
                    continue;
                };
                if !ran[i] && wakeup.take() {
                    c.run_cycle();
                    ran[i] = true;
                    any = true;
                }
            }
            if !any {
                break;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_timeline_is_the_union_of_the_release_instants() {
        let ms = Duration::from_millis;
        let t = Timeline::new(&[ms(20), ms(50), ms(20)], Some(3), None);
        let mut instants = Vec::new();
        let mut previous = None;
        while let Some(n) = t.next(previous) {
            instants.push(n / 1_000_000);
            previous = Some(n);
        }
        // Three cycles of the fastest container (20 ms): the instants before 60 ms,
        // 0, 20, 40 of the 20 ms container and 0, 50 of the 50 ms one.
        assert_eq!(instants, [0, 20, 40, 50]);
        let only_data = Timeline::new(&[], Some(2), None);
        assert_eq!(only_data.next(None), Some(0));
        assert_eq!(only_data.next(Some(0)), Some(1_000_000));
        assert_eq!(only_data.next(Some(1_000_000)), None);
        // `--for 45ms` of model time: the instants up to 45 ms, whatever the limit.
        let short = Timeline::new(&[ms(20), ms(50)], None, Some(ms(45)));
        assert_eq!(short.next(Some(20_000_000)), Some(40_000_000));
        assert_eq!(short.next(Some(40_000_000)), None);
    }
}
