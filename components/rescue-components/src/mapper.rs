//! `rescue.Mapper`: integrates laser scans into an occupancy grid and publishes it now
//! and then.

use crate::types::{LaserScan, Map, Pose2D, UNKNOWN};
use ferroc_runtime::module::{In, Module, ModuleType, Out, Parameter, Setup};
use ferroc_runtime::resource::LockSlot;
use std::time::Duration;

/// What one observation adds to a cell: free space lowers it, a hit raises it.
const FREE_STEP: i8 = 20;
const HIT_STEP: i8 = 40;
/// The largest grid this mapper builds (cells): 4000 × 4000, 16 MB.
pub const MAX_CELLS: u64 = 16_000_000;

/// A square grid of `size` metres centred on the map origin, every cell unknown.
/// `None` if it would have more than [`MAX_CELLS`] cells.
pub fn empty_map(resolution: f64, size: f64) -> Option<Map> {
    if !(resolution > 0.0 && size > 0.0) {
        return None;
    }
    let side = (size / resolution).ceil();
    if side * side > MAX_CELLS as f64 {
        return None;
    }
    let side = side as u32;
    let half = f64::from(side) * resolution / 2.0;
    Some(Map {
        resolution,
        width: side,
        height: side,
        origin: Pose2D {
            x: -half,
            y: -half,
            theta: 0.0,
        },
        cells: vec![UNKNOWN; side as usize * side as usize],
    })
}

fn observe(map: &mut Map, x: f64, y: f64, hit: bool) {
    let Some((cx, cy)) = map.cell_of(x, y) else {
        return;
    };
    let i = cy as usize * map.width as usize + cx as usize;
    let Some(cell) = map.cells.get_mut(i) else {
        return;
    };
    let before = if *cell == UNKNOWN { 50 } else { *cell };
    *cell = if hit {
        before.saturating_add(HIT_STEP).min(100)
    } else {
        before.saturating_sub(FREE_STEP).max(0)
    };
}

/// Marks the cells each beam crossed as freer and the cell it ended in as more
/// occupied. A beam without a return (intensity 0: nothing within the maximum range)
/// hit nothing.
pub fn integrate(map: &mut Map, scan: &LaserScan, pose: &Pose2D) {
    let step = map.resolution / 2.0;
    if step.is_nan() || step <= 0.0 {
        return;
    }
    // No beam can cross more of the map than its diagonal.
    let longest = f64::from(map.width).hypot(f64::from(map.height)) * map.resolution;
    for (i, &range) in scan.ranges.iter().enumerate() {
        if !range.is_finite() || range <= 0.0 {
            continue;
        }
        let hit = scan.intensities.get(i).is_none_or(|&x| x > 0.0);
        let angle = pose.theta + scan.bearing(i);
        let (dx, dy) = (angle.cos(), angle.sin());
        let range = f64::from(range).min(longest);
        let mut last = None;
        let mut t = 0.0;
        while t < range - step {
            let (x, y) = (pose.x + t * dx, pose.y + t * dy);
            let cell = map.cell_of(x, y);
            if cell.is_some() && cell != last {
                observe(map, x, y, false);
                last = cell;
            }
            t += step;
        }
        if hit {
            observe(map, pose.x + range * dx, pose.y + range * dy, true);
        }
    }
}

/// Keeps the grid under its lock while integrating queued scans at the latest pose.
pub struct Mapper {
    scan: In<LaserScan>,
    pose: In<Pose2D>,
    map_out: Out<Map>,
    resolution: Parameter<f64>,
    size: Parameter<f64>,
    publish_period: Parameter<Duration>,
    map_lock: LockSlot,
    map: Option<Map>,
    /// Stamp of the last scan that was published with the map.
    published: Option<Duration>,
}

impl ModuleType for Mapper {
    const NAME: &'static str = "rescue.Mapper";
    const DOC: &'static str = "Occupancy-grid mapping from scans and poses";

    fn create(m: &mut Setup<'_>) -> Self {
        Mapper {
            scan: m.input("scan").required().build(),
            pose: m.input("pose").required().build(),
            map_out: m.output("map").build(),
            resolution: m
                .param("resolution")
                .unit("m")
                .range(0.01, 1.0)
                .default(0.05)
                .build(),
            size: m
                .param("size")
                .unit("m")
                .range(5.0, 500.0)
                .default(50.0)
                .build(),
            publish_period: m
                .param("publish_period")
                .range(0.1, 60.0)
                .default(Duration::from_secs(1))
                .build(),
            map_lock: m.lock("map_lock"),
            map: None,
            published: None,
        }
    }
}

impl Module for Mapper {
    fn update(&mut self) {
        if self.map.is_none() {
            // Allocated in the first step, not in `create` (which also describes the type).
            let (resolution, size) = (self.resolution.get(), self.size.get());
            self.map = empty_map(resolution, size).or_else(|| {
                ferroc_runtime::console::line(&format!(
                    "error: mapper: a {size} m map at {resolution} m has more than {MAX_CELLS} cells; mapping is off"
                ));
                Some(Map::default())
            });
        }
        let pose = self.pose.get();
        let mut latest = None;
        {
            let _grid = self.map_lock.lock();
            let Some(map) = self.map.as_mut() else {
                return;
            };
            // Every queued scan (`queue=N` in the model), or the latest one if new.
            while let Some(scan) = self.scan.try_pop() {
                integrate(map, &scan, &pose);
                latest = Some(scan.stamp);
            }
        }
        let Some(now) = latest else {
            return;
        };
        let due = self
            .published
            .is_none_or(|last| now >= last + self.publish_period.get());
        if due {
            self.published = Some(now);
            if let Some(map) = &self.map {
                self.map_out.publish_with(|out| out.clone_from(map));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drivers::sweep;
    use crate::hardware::Robot;
    use crate::types::OCCUPIED;

    #[test]
    fn a_scan_marks_the_walls_occupied_and_the_room_free() {
        let robot = Robot::default();
        let mut map = empty_map(0.05, 40.0).unwrap();
        let scan = sweep(&robot, &robot.pose, 30.0, Duration::ZERO);
        integrate(&mut map, &scan, &robot.pose);
        let at = |map: &Map, x: f64, y: f64| {
            let (cx, cy) = map.cell_of(x, y).unwrap();
            map.get(cx, cy)
        };
        // The partition 6 m ahead (x = 2: the hit lands in the cell just east of it
        // or on it) is occupied, the floor between free, beyond it unknown.
        let partition = at(&map, 2.0 + 0.01, 0.0).max(at(&map, 2.0 - 0.01, 0.0));
        assert!(partition >= OCCUPIED, "{partition}");
        assert_eq!(at(&map, -1.0, 0.0), 30);
        assert_eq!(at(&map, 4.0, 0.0), UNKNOWN);
        // Behind the robot (the laser looks forward only) nothing is known.
        assert_eq!(at(&map, -5.5, 0.0), UNKNOWN);
        // A second scan makes the floor freer.
        integrate(&mut map, &scan, &robot.pose);
        assert_eq!(at(&map, -1.0, 0.0), 10);
    }

    #[test]
    fn absurd_ranges_are_cut_at_the_map() {
        let mut map = empty_map(0.05, 10.0).unwrap();
        let scan = LaserScan {
            stamp: Duration::ZERO,
            angle_min: 0.0,
            angle_increment: 0.01,
            ranges: vec![1e30, f32::NAN, -1.0, 2.0],
            intensities: vec![1.0; 4],
        };
        integrate(&mut map, &scan, &Pose2D::default());
        // The 2 m beam (4th) hit something; the huge one marked the map to its edge.
        let (cx, cy) = map
            .cell_of(2.0 * 0.03f64.cos(), 2.0 * 0.03f64.sin())
            .unwrap();
        assert!(map.get(cx, cy) >= crate::types::OCCUPIED);
        let (ex, ey) = map.cell_of(4.9, 0.0).unwrap();
        assert_eq!(map.get(ex, ey), 30);
    }

    #[test]
    fn impossible_grids_are_refused() {
        assert!(empty_map(0.0, 50.0).is_none());
        assert!(empty_map(0.01, 500.0).is_none()); // 50 000² cells
        assert!(empty_map(f64::NAN, 50.0).is_none());
        let map = empty_map(0.05, 80.0).unwrap();
        assert_eq!((map.width, map.height), (1600, 1600));
        assert_eq!(map.cell_of(0.0, 0.0), Some((800, 800)));
    }
}
