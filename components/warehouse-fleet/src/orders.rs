//! `warehouse.WmsBridge`: order intake from the warehouse management system.
//!
//! The simulation stands in for the WMS's REST API: at every poll it hands over the
//! orders that "arrived" since the last one, drawn from a fixed-seed sequence keyed by
//! the site, so the same site gives the same orders on every run.

use crate::sequence::Sequence;
use crate::timing::DISPATCH_STEP;
use crate::{Pose2D, Task};
use ferroc_runtime::module::{Module, ModuleType, Out, Parameter, Setup};
use std::time::Duration;

/// Storage rows (x) and aisles (y) of the shelf grid, metres.
const SHELF_ROWS: [f64; 4] = [5.0, 7.0, 9.0, 11.0];
const SHELF_AISLES: [f64; 4] = [0.0, 1.5, 3.0, 4.5];
/// Pick stations along the wall at x = 0.5 m.
const STATION_X: f64 = 0.5;
const STATIONS_Y: [f64; 3] = [0.0, 2.0, 4.0];
/// Time allowed for an order of the lowest priority; each priority step takes 30 s off.
const DEADLINE: f64 = 240.0;

/// Produces the orders of one site, poll by poll.
#[derive(Clone, Debug)]
pub struct OrderGenerator {
    sequence: Sequence,
    next_id: u64,
}

impl OrderGenerator {
    /// The orders of `site` (a different site, different orders).
    pub fn new(site: &str) -> Self {
        OrderGenerator {
            sequence: Sequence::from_text(site),
            next_id: 1,
        }
    }

    fn pick<T: Copy>(&mut self, from: &[T]) -> T {
        from[(self.sequence.next() % from.len() as u64) as usize]
    }

    /// The orders of one poll at model time `now` seconds: none most of the time, one
    /// or two now and then (0.45 per poll on average).
    pub fn poll(&mut self, now: f64) -> Vec<Task> {
        let count = match self.sequence.next() % 20 {
            0..=11 => 0,
            12..=18 => 1,
            _ => 2,
        };
        (0..count)
            .map(|_| {
                let pickup = Pose2D {
                    x: self.pick(&SHELF_ROWS),
                    y: self.pick(&SHELF_AISLES),
                    theta: 0.0,
                };
                let dropoff = Pose2D {
                    x: STATION_X,
                    y: self.pick(&STATIONS_Y),
                    theta: 0.0,
                };
                let level = self.sequence.next() % 4;
                let id = self.next_id;
                self.next_id += 1;
                Task {
                    id,
                    pickup,
                    dropoff,
                    priority: (level * 64) as u8,
                    deadline: Duration::try_from_secs_f64(now + DEADLINE - 30.0 * level as f64)
                        .unwrap_or(Duration::MAX),
                }
            })
            .collect()
    }
}

/// The bridge to the WMS: polls every `poll_period` and publishes each new order.
pub struct WmsBridge {
    orders: Out<Task>,
    // The simulation serves the orders itself; a real bridge would call this URL.
    #[allow(dead_code)]
    endpoint: Parameter<String>,
    poll_period: Parameter<Duration>,
    site: Parameter<String>,
    generator: Option<OrderGenerator>,
    cycle: u64,
}

impl ModuleType for WmsBridge {
    const NAME: &'static str = "warehouse.WmsBridge";
    const DOC: &'static str = "Bridge to the warehouse management system (REST)";

    fn create(m: &mut Setup<'_>) -> Self {
        WmsBridge {
            orders: m.output("orders").build(),
            endpoint: m.param("endpoint").build(),
            poll_period: m
                .param("poll_period")
                .range(0.1, 60.0)
                .default(Duration::from_secs(1))
                .build(),
            site: m.param("site").default("main".to_string()).build(),
            generator: None,
            cycle: 0,
        }
    }
}

impl Module for WmsBridge {
    fn update(&mut self) {
        let every = (self.poll_period.get().as_secs_f64() / DISPATCH_STEP)
            .round()
            .max(1.0) as u64;
        let cycle = self.cycle;
        self.cycle += 1;
        if cycle % every != 0 {
            return;
        }
        if self.generator.is_none() || self.site.changed() {
            self.generator = Some(OrderGenerator::new(self.site.value()));
        }
        let Some(generator) = self.generator.as_mut() else {
            return;
        };
        for task in generator.poll(cycle as f64 * DISPATCH_STEP) {
            self.orders.publish(task);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orders_are_reproducible_numbered_and_on_the_grid() {
        let mut a = OrderGenerator::new("hamburg_dc2");
        let mut b = OrderGenerator::new("hamburg_dc2");
        let mut all = Vec::new();
        for poll in 0..200 {
            let (x, y) = (a.poll(poll as f64), b.poll(poll as f64));
            assert_eq!(x, y);
            all.extend(x);
        }
        // About 0.45 orders per poll.
        assert!((50..=130).contains(&all.len()), "{}", all.len());
        for (k, t) in all.iter().enumerate() {
            assert_eq!(t.id, k as u64 + 1);
            assert!(SHELF_ROWS.contains(&t.pickup.x) && SHELF_AISLES.contains(&t.pickup.y));
            assert!(t.dropoff.x == STATION_X && STATIONS_Y.contains(&t.dropoff.y));
            assert!([0, 64, 128, 192].contains(&t.priority));
        }
        // Higher priority, earlier deadline (for orders of the same poll time).
        let urgent = all.iter().find(|t| t.priority == 192).unwrap();
        let deadline = urgent.deadline.as_secs_f64();
        assert!(deadline < DEADLINE + 200.0 - 30.0 * 2.0);
        // Another site, other orders.
        let mut c = OrderGenerator::new("berlin");
        let other: Vec<Task> = (0..200).flat_map(|p| c.poll(p as f64)).collect();
        assert_ne!(other, all);
    }
}
