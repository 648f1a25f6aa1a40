//! A coarse planning grid made from the occupancy map: what the planner and the mission
//! manager search. Planning on 25 cm cells instead of the mapper's 5 cm keeps a search
//! over the whole building to a few thousand cells.

use crate::types::{Map, OCCUPIED, UNKNOWN};
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Edge length of a planning cell (m).
pub const CELL: f64 = 0.25;

/// What is known of a planning cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cell {
    /// Nothing observed.
    Unknown,
    /// Observed free.
    Free,
    /// Free or unknown, but close to an obstacle: passable at a higher cost, so paths
    /// keep their distance where there is room and the robot can leave such a cell.
    Near,
    /// Holds an obstacle, or lies within the robot's radius of one.
    Blocked,
}

/// A coarse grid over the map.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    origin: (f64, f64),
    /// Edge length of a cell: [`CELL`], or the map's resolution if that is coarser.
    step: f64,
    width: usize,
    height: usize,
    cells: Vec<Cell>,
}

/// Cost of a straight and of a diagonal step (cells × 10).
const STRAIGHT: u32 = 10;
const DIAGONAL: u32 = 14;
/// Unreachable.
pub const FAR: u32 = u32::MAX;
/// A step into a [`Cell::Near`] costs this many times a step into open space.
const NEAR_PENALTY: u32 = 4;

impl Grid {
    /// The planning grid of `map`: cells within `radius` of an obstacle blocked, those
    /// within `radius + clearance` near.
    pub fn from_map(map: &Map, radius: f64, clearance: f64) -> Grid {
        let k = ((CELL / map.resolution).round().max(1.0) as usize).max(1);
        let (fw, fh) = (map.width as usize, map.height as usize);
        let (width, height) = (fw.div_ceil(k), fh.div_ceil(k));
        let mut cells = vec![Cell::Unknown; width * height];
        if map.cells.len() == fw * fh && fw > 0 {
            // Row by row, `k` map cells per planning cell: no division per map cell
            // (a 80 m map at 5 cm has 2.56 million of them).
            for (y, row) in map.cells.chunks_exact(fw).enumerate() {
                let out = &mut cells[(y / k) * width..][..width];
                for (cell, chunk) in out.iter_mut().zip(row.chunks(k)) {
                    for &v in chunk {
                        if v >= OCCUPIED {
                            *cell = Cell::Blocked;
                        } else if v != UNKNOWN && *cell == Cell::Unknown {
                            *cell = Cell::Free;
                        }
                    }
                }
            }
        }
        let step = map.resolution * k as f64;
        let mut grid = Grid {
            origin: (map.origin.x, map.origin.y),
            step,
            width,
            height,
            cells,
        };
        // Radii in cells, from cell centre to cell centre.
        let cells = |m: f64| (m.max(0.0) / step).min(1e3);
        let lethal = cells(radius).round() as i64;
        grid.inflate(
            lethal,
            (cells(radius + clearance.max(0.0)).ceil() as i64).max(lethal),
        );
        grid
    }

    /// Marks cells within `lethal` cells of an obstacle blocked, within `near` near.
    fn inflate(&mut self, lethal: i64, near: i64) {
        let obstacles: Vec<usize> = (0..self.cells.len())
            .filter(|&i| self.cells[i] == Cell::Blocked)
            .collect();
        for i in obstacles {
            let (x, y) = ((i % self.width) as i64, (i / self.width) as i64);
            for dy in -near..=near {
                for dx in -near..=near {
                    let d2 = dx * dx + dy * dy;
                    let Some(j) = self.index(x + dx, y + dy) else {
                        continue;
                    };
                    if d2 <= lethal * lethal {
                        self.cells[j] = Cell::Blocked;
                    } else if d2 <= near * near && self.cells[j] != Cell::Blocked {
                        self.cells[j] = Cell::Near;
                    }
                }
            }
        }
    }

    fn index(&self, x: i64, y: i64) -> Option<usize> {
        let inside = (0..self.width as i64).contains(&x) && (0..self.height as i64).contains(&y);
        inside.then(|| y as usize * self.width + x as usize)
    }

    /// The cell holding the map-frame point, if on the grid.
    pub fn cell_of(&self, x: f64, y: f64) -> Option<usize> {
        let step = self.step();
        let (cx, cy) = ((x - self.origin.0) / step, (y - self.origin.1) / step);
        if !(cx.is_finite() && cy.is_finite()) {
            return None;
        }
        self.index(cx.floor() as i64, cy.floor() as i64)
    }

    /// Map-frame centre of cell `i`.
    pub fn centre(&self, i: usize) -> (f64, f64) {
        let step = self.step();
        (
            self.origin.0 + ((i % self.width) as f64 + 0.5) * step,
            self.origin.1 + ((i / self.width) as f64 + 0.5) * step,
        )
    }

    /// Edge length of a cell (m).
    pub fn step(&self) -> f64 {
        self.step
    }

    /// What is known of cell `i`.
    pub fn get(&self, i: usize) -> Cell {
        self.cells.get(i).copied().unwrap_or(Cell::Blocked)
    }

    /// Path costs (×10 per cell, [`NEAR_PENALTY`] times that near obstacles) from
    /// `from` to every cell, moving through all but blocked cells in 8 directions
    /// (Dijkstra). A blocked start (the robot grazing a wall) may still leave its cell.
    pub fn costs_from(&self, from: usize) -> Vec<u32> {
        let mut cost = vec![FAR; self.cells.len()];
        if from >= self.cells.len() {
            return cost;
        }
        let mut heap = BinaryHeap::from([Reverse((0u32, from))]);
        cost[from] = 0;
        while let Some(Reverse((c, i))) = heap.pop() {
            if c > cost[i] {
                continue;
            }
            let (x, y) = ((i % self.width) as i64, (i / self.width) as i64);
            for (dx, dy) in NEIGHBOURS {
                let Some(j) = self.index(x + dx, y + dy) else {
                    continue;
                };
                if self.cells[j] == Cell::Blocked {
                    continue;
                }
                let step = if dx != 0 && dy != 0 {
                    DIAGONAL
                } else {
                    STRAIGHT
                };
                let penalty = if self.cells[j] == Cell::Near {
                    NEAR_PENALTY
                } else {
                    1
                };
                let next = c.saturating_add(step * penalty);
                if next < cost[j] {
                    cost[j] = next;
                    heap.push(Reverse((next, j)));
                }
            }
        }
        cost
    }

    /// The cell after `i` on the cheapest path down `costs` (towards cost 0).
    pub fn downhill(&self, costs: &[u32], i: usize) -> Option<usize> {
        let (x, y) = ((i % self.width) as i64, (i / self.width) as i64);
        NEIGHBOURS
            .iter()
            .filter_map(|(dx, dy)| self.index(x + dx, y + dy))
            .filter(|&j| {
                costs
                    .get(j)
                    .is_some_and(|&c| c < costs.get(i).copied().unwrap_or(FAR))
            })
            .min_by_key(|&j| costs[j])
    }

    /// Column and row of cell `i`.
    pub fn coords(&self, i: usize) -> (i64, i64) {
        (
            (i % self.width.max(1)) as i64,
            (i / self.width.max(1)) as i64,
        )
    }

    /// The cell at column `x`, row `y`, if on the grid.
    pub fn at(&self, x: i64, y: i64) -> Option<usize> {
        self.index(x, y)
    }

    /// Whether the straight line from `from` to `to` crosses no blocked cell (the cell
    /// of `from` itself does not count: the robot may graze an inflated wall).
    pub fn clear_line(&self, from: (f64, f64), to: (f64, f64)) -> bool {
        let start = self.cell_of(from.0, from.1);
        let length = (to.0 - from.0).hypot(to.1 - from.1);
        let steps = (length / (self.step / 2.0)).ceil().max(1.0) as usize;
        (1..=steps).all(|k| {
            let t = k as f64 / steps as f64;
            let cell = self.cell_of(from.0 + t * (to.0 - from.0), from.1 + t * (to.1 - from.1));
            cell == start || cell.is_some_and(|c| self.cells[c] != Cell::Blocked)
        })
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.cells.len()
    }
}

/// The four straight neighbours, then the diagonals.
const NEIGHBOURS: [(i64, i64); 8] = [
    (1, 0),
    (-1, 0),
    (0, 1),
    (0, -1),
    (1, 1),
    (1, -1),
    (-1, 1),
    (-1, -1),
];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drivers::sweep;
    use crate::hardware::Robot;
    use crate::mapper::{empty_map, integrate};
    use std::time::Duration;

    fn mapped_start() -> Grid {
        let robot = Robot::default();
        let mut map = empty_map(0.05, 40.0).unwrap();
        integrate(
            &mut map,
            &sweep(&robot, &robot.pose, 30.0, Duration::ZERO),
            &robot.pose,
        );
        Grid::from_map(&map, 0.3, 0.3)
    }

    #[test]
    fn the_scan_makes_free_cells_blocked_walls_and_frontiers() {
        let grid = mapped_start();
        let at = |x, y| grid.get(grid.cell_of(x, y).unwrap());
        assert_eq!(at(-1.0, 0.0), Cell::Free);
        assert_eq!(at(2.0, 0.0), Cell::Blocked);
        assert_eq!(at(1.8, 0.0), Cell::Blocked, "within the radius");
        assert_eq!(at(1.4, 0.0), Cell::Near, "within radius and clearance");
        assert_eq!(at(1.1, 0.0), Cell::Free);
        assert_eq!(at(-5.5, 0.0), Cell::Unknown, "behind the robot");
        // Lines of sight end at walls.
        assert!(grid.clear_line((-4.0, 0.0), (-1.0, 2.0)));
        assert!(!grid.clear_line((-4.0, 0.0), (3.0, 0.0)));
    }

    #[test]
    fn paths_go_round_walls() {
        let grid = mapped_start();
        let from = grid.cell_of(-4.0, 0.0).unwrap();
        let costs = grid.costs_from(from);
        // 3 m straight east: 12 cells of 25 cm, cost 120.
        assert_eq!(costs[grid.cell_of(-1.0 + 0.01, 0.01).unwrap()], 120);
        // Beyond the partition (x = 2) the path goes round its north end (y = 1),
        // longer than the 7 m straight line.
        let beyond = costs[grid.cell_of(3.0, 0.0).unwrap()];
        assert!(beyond != FAR && beyond > 280 + 20, "{beyond}");
        // Following the path downhill from there leads back to the start.
        let mut at = grid.cell_of(3.0, 0.0).unwrap();
        for _ in 0..200 {
            match grid.downhill(&costs, at) {
                Some(next) => at = next,
                None => break,
            }
        }
        assert_eq!(at, from);
    }
}
