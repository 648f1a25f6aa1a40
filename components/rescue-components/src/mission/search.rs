//! Where the station has looked for victims: the floor the camera has seen from close
//! enough to detect a victim. The laser maps a room from its door long before the
//! camera has seen its corners, so exploring for victims means covering the floor
//! with the camera, not only completing the map.

use crate::grid::{Cell, Grid, FAR};
use crate::types::Pose2D;

/// Floor within this distance of the camera is searched (m): a victim there shows
/// clearly enough to pass the detector's usual threshold.
pub const SEARCH_RANGE: f64 = 3.5;
/// Half the angle searched either side of the heading: a little less than half the
/// camera's field of view, for victims lying across its edge.
const HALF_ANGLE: f64 = 0.45;

/// Which planning cells the camera has searched.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Searched {
    cells: Vec<bool>,
}

impl Searched {
    /// Marks the free cells the camera sees from `pose`: within [`SEARCH_RANGE`], within
    /// the field of view and in line of sight on `grid`.
    pub fn look(&mut self, grid: &Grid, pose: &Pose2D) {
        if self.cells.len() != grid.len() {
            self.cells = vec![false; grid.len()]; // a grid of another size: start over
        }
        let Some(centre) = grid.cell_of(pose.x, pose.y) else {
            return; // off the grid (or an empty grid)
        };
        if grid.step().is_nan() || grid.step() <= 0.0 {
            return;
        }
        let (cx, cy) = grid.coords(centre);
        let reach = (SEARCH_RANGE / grid.step()).ceil() as i64;
        for y in cy - reach..=cy + reach {
            for x in cx - reach..=cx + reach {
                let Some(i) = grid.at(x, y) else { continue };
                if self.cells[i] || grid.get(i) != Cell::Free {
                    continue;
                }
                let (px, py) = grid.centre(i);
                let (dx, dy) = (px - pose.x, py - pose.y);
                let bearing = crate::types::wrap_angle(dy.atan2(dx) - pose.theta);
                if dx.hypot(dy) <= SEARCH_RANGE
                    && bearing.abs() <= HALF_ANGLE
                    && grid.clear_line((pose.x, pose.y), (px, py))
                {
                    self.cells[i] = true;
                }
            }
        }
    }

    /// Counts cell `i` as searched (a goal there could not be reached).
    pub fn mark(&mut self, i: usize) {
        if let Some(c) = self.cells.get_mut(i) {
            *c = true;
        }
    }

    /// Whether cell `i` has been searched.
    pub fn contains(&self, i: usize) -> bool {
        self.cells.get(i).copied().unwrap_or(false)
    }

    /// Free, unsearched cells within two cells of `i` (itself included).
    fn unsearched_around(&self, grid: &Grid, i: usize) -> usize {
        let (x, y) = grid.coords(i);
        let mut n = 0;
        for dy in -2..=2 {
            for dx in -2..=2 {
                if let Some(j) = grid.at(x + dx, y + dy) {
                    n += usize::from(grid.get(j) == Cell::Free && !self.contains(j));
                }
            }
        }
        n
    }
}

/// The nearest reachable patch of unsearched floor: a free cell at least a metre's
/// path from the robot, within `radius` of `home`, with at least `min_count`
/// unsearched free cells around it. The goal faces it from the robot.
pub fn nearest_unsearched(
    grid: &Grid,
    searched: &Searched,
    robot: &Pose2D,
    home: &Pose2D,
    radius: f64,
    min_count: usize,
) -> Option<Pose2D> {
    let start = grid.cell_of(robot.x, robot.y)?;
    let costs = grid.costs_from(start);
    let near = (10.0 / grid.step()) as u32; // one metre, in path cost units
    (0..grid.len())
        .filter(|&i| costs[i] != FAR && costs[i] >= near)
        .filter(|&i| grid.get(i) == Cell::Free && !searched.contains(i))
        .filter(|&i| {
            let (x, y) = grid.centre(i);
            (x - home.x).hypot(y - home.y) <= radius
        })
        .filter(|&i| searched.unsearched_around(grid, i) >= min_count)
        .min_by_key(|&i| (costs[i], i))
        .map(|i| {
            let (x, y) = grid.centre(i);
            Pose2D {
                x,
                y,
                theta: (y - robot.y).atan2(x - robot.x),
            }
        })
}
