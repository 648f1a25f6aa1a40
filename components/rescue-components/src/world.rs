//! The simulated building the robot explores: walls, victims and line-of-sight
//! geometry. Pure functions of the geometry, so drivers and tests share them.

/// A straight wall from `a` to `b` (map frame, metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wall {
    /// One end.
    pub a: (f64, f64),
    /// The other end.
    pub b: (f64, f64),
}

/// Walls and victims of a building.
#[derive(Clone, Debug, PartialEq)]
pub struct World {
    /// Every wall, outer and inner.
    pub walls: Vec<Wall>,
    /// Where victims lie (on the floor: below the laser's plane, so the laser does not
    /// see them, but walls hide them from the camera).
    pub victims: Vec<(f64, f64)>,
}

/// The pose every simulated robot starts from.
pub const START: (f64, f64, f64) = (-4.0, 0.0, 0.0);

impl World {
    /// A collapsed building of 16 m × 10 m: two partitions split it into three rooms
    /// joined by gaps at opposite ends, and a victim lies in each room. The robot starts
    /// in the western room facing east; the first victim is in view, the others are
    /// hidden behind the partitions until the robot goes round them.
    pub fn building() -> World {
        let w = |a: (f64, f64), b: (f64, f64)| Wall { a, b };
        World {
            walls: vec![
                w((-6.0, -5.0), (10.0, -5.0)),
                w((10.0, -5.0), (10.0, 5.0)),
                w((10.0, 5.0), (-6.0, 5.0)),
                w((-6.0, 5.0), (-6.0, -5.0)),
                // Partition west|middle, open in the north (y 1..5).
                w((2.0, -5.0), (2.0, 1.0)),
                // Partition middle|east, open in the south (y -5..-1).
                w((6.0, -1.0), (6.0, 5.0)),
            ],
            victims: vec![(0.0, 1.2), (4.0, -3.5), (8.5, 3.5)],
        }
    }

    /// Distance from `from` along `angle` to the nearest wall, at most `max`.
    pub fn ray(&self, from: (f64, f64), angle: f64, max: f64) -> f64 {
        let dir = (angle.cos(), angle.sin());
        self.walls
            .iter()
            .filter_map(|w| ray_hits(from, dir, w))
            .fold(max, f64::min)
    }

    /// Whether no wall stands between `from` and `to`.
    pub fn line_of_sight(&self, from: (f64, f64), to: (f64, f64)) -> bool {
        let (dx, dy) = (to.0 - from.0, to.1 - from.1);
        let length = dx.hypot(dy);
        if length < 1e-9 {
            return true;
        }
        let dir = (dx / length, dy / length);
        self.walls
            .iter()
            .filter_map(|w| ray_hits(from, dir, w))
            .all(|d| d >= length - 1e-9)
    }

    /// Distance from `p` to the nearest wall.
    pub fn clearance(&self, p: (f64, f64)) -> f64 {
        self.walls
            .iter()
            .map(|w| point_segment_distance(p, w))
            .fold(f64::INFINITY, f64::min)
    }
}

/// Distance along the unit direction `dir` from `from` to the wall, if the ray hits it.
fn ray_hits(from: (f64, f64), dir: (f64, f64), w: &Wall) -> Option<f64> {
    let e = (w.b.0 - w.a.0, w.b.1 - w.a.1);
    let denom = cross(dir, e);
    if denom.abs() < 1e-12 {
        return None; // parallel
    }
    let rel = (w.a.0 - from.0, w.a.1 - from.1);
    let t = cross(rel, e) / denom; // along the ray
    let u = cross(rel, dir) / denom; // along the wall
    (t >= 0.0 && (0.0..=1.0).contains(&u)).then_some(t)
}

fn cross(a: (f64, f64), b: (f64, f64)) -> f64 {
    a.0 * b.1 - a.1 * b.0
}

fn point_segment_distance(p: (f64, f64), w: &Wall) -> f64 {
    let e = (w.b.0 - w.a.0, w.b.1 - w.a.1);
    let len2 = e.0 * e.0 + e.1 * e.1;
    let t = if len2 < 1e-12 {
        0.0
    } else {
        (((p.0 - w.a.0) * e.0 + (p.1 - w.a.1) * e.1) / len2).clamp(0.0, 1.0)
    };
    (p.0 - w.a.0 - t * e.0).hypot(p.1 - w.a.1 - t * e.1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rays_measure_the_distance_to_the_first_wall() {
        let world = World::building();
        // From the start, east: the west|middle partition at x = 2 is 6 m away.
        assert!((world.ray((-4.0, 0.0), 0.0, 30.0) - 6.0).abs() < 1e-9);
        // West: the outer wall at x = -6.
        assert!((world.ray((-4.0, 0.0), std::f64::consts::PI, 30.0) - 2.0).abs() < 1e-9);
        // North-east at 45°: the north wall (y = 5) is 5·√2 away, before anything else.
        let d = world.ray((-4.0, 0.0), std::f64::consts::FRAC_PI_4, 30.0);
        assert!((d - 5.0 * 2f64.sqrt()).abs() < 1e-9, "{d}");
        // Through the gap north of the partition: the east wall of the middle room is
        // the partition at x = 6, 4 m from (2, 3).
        assert!((world.ray((2.0, 3.0), 0.0, 30.0) - 4.0).abs() < 1e-9);
        // Limited by the maximum range.
        assert_eq!(world.ray((-4.0, 0.0), 0.0, 2.5), 2.5);
    }

    #[test]
    fn partitions_hide_victims() {
        let world = World::building();
        let start = (START.0, START.1);
        assert!(world.line_of_sight(start, world.victims[0]));
        assert!(!world.line_of_sight(start, world.victims[1]));
        assert!(!world.line_of_sight(start, world.victims[2]));
        // From the middle room's north gap the second victim is in view.
        assert!(world.line_of_sight((3.0, 3.0), world.victims[1]));
    }

    #[test]
    fn clearance_is_the_distance_to_the_nearest_wall() {
        let world = World::building();
        assert!((world.clearance((-4.0, 0.0)) - 2.0).abs() < 1e-9);
        // Beyond the end of the west partition (2, 1): distance to its end point.
        assert!((world.clearance((2.0, 2.0)) - 1.0).abs() < 1e-9);
    }
}
