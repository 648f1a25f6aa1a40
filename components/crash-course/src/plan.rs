//! Where to drive next, from one look around: the controller's planning, free of ports.
//!
//! The robot's infrared sensors are two rays (front and rear). A ray says nothing about
//! what is beside the robot, so a robot that only reacts to its front ray scrapes walls
//! it drives along at a shallow angle, and one noisy reading near a wall is enough to
//! speed into it. Instead the controller turns in place once (half a turn: the rear ray
//! covers the other half), keeps every reading as a point where something may be, and
//! then drives straight only as far as the corridor its body sweeps is free of points.
//!
//! Every reading is an obstacle point, also one at the sensor's maximum range: the space
//! beyond it was not seen, so no corridor reaches past what the rays saw. A reading is
//! the distance from the bumper, taken here from the centre: walls look closer than they
//! are, never farther. Noise that makes a wall look closer only shortens a drive; a
//! reading too far is outvoted by its neighbours, which lie in the same corridor.

/// One reading: the direction of the ray (radians, arena frame) and what it measured.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reading {
    pub heading: f64,
    pub range: f64,
}

/// A straight drive: the heading to turn to, and how far it is safe to go.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Drive {
    pub heading: f64,
    pub distance: f64,
}

/// How far the robot may drive along `heading` from where `readings` were taken: up to
/// `max` metres, stopping `half_width` short of any point within `half_width` of the
/// line it drives on.
pub fn free_distance(readings: &[Reading], heading: f64, half_width: f64, max: f64) -> f64 {
    let (ux, uy) = (heading.cos(), heading.sin());
    let mut free = max;
    for r in readings {
        let (px, py) = (r.range * r.heading.cos(), r.range * r.heading.sin());
        let along = px * ux + py * uy;
        let beside = (py * ux - px * uy).abs();
        if along > 0.0 && beside < half_width {
            free = free.min(along - half_width);
        }
    }
    free.max(0.0)
}

/// The drive that goes farthest, over the directions the rays looked in; ties go to the
/// first direction looked in (the scan's order), so a run repeats exactly.
pub fn choose(readings: &[Reading], half_width: f64, max: f64) -> Drive {
    let mut best = Drive {
        heading: readings.first().map_or(0.0, |r| r.heading),
        distance: 0.0,
    };
    for r in readings {
        let distance = free_distance(readings, r.heading, half_width, max);
        if distance > best.distance + 1e-9 {
            best = Drive {
                heading: r.heading,
                distance,
            };
        }
    }
    best
}

/// The drive from `at` towards `goal` (x, y), at most `max` metres; `None` within
/// `tolerance` of it.
pub fn toward(goal: (f64, f64), at: (f64, f64), tolerance: f64, max: f64) -> Option<Drive> {
    let (dx, dy) = (goal.0 - at.0, goal.1 - at.1);
    let distance = dx.hypot(dy);
    (distance >= tolerance).then(|| Drive {
        heading: dy.atan2(dx),
        distance: distance.min(max),
    })
}

/// `angle` in (−π, π].
pub fn wrap(angle: f64) -> f64 {
    let a = angle.rem_euclid(std::f64::consts::TAU);
    if a > std::f64::consts::PI {
        a - std::f64::consts::TAU
    } else {
        a
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, PI};

    /// Readings every `step` radians around a robot at (x, y) in a square arena of
    /// half-size `half`, as a ray of range `max` sees it (from the centre).
    fn look_around(x: f64, y: f64, half: f64, max: f64, step: f64) -> Vec<Reading> {
        let mut out = Vec::new();
        let mut heading = 0.0;
        while heading < 2.0 * PI {
            let (dx, dy) = (heading.cos(), heading.sin());
            let along = |p: f64, d: f64| {
                if d > 1e-9 {
                    (half - p) / d
                } else if d < -1e-9 {
                    (-half - p) / d
                } else {
                    f64::INFINITY
                }
            };
            let range = along(x, dx).min(along(y, dy)).min(max);
            out.push(Reading { heading, range });
            heading += step;
        }
        out
    }

    #[test]
    fn a_wall_ahead_shortens_the_drive_by_the_half_width() {
        // A wall 1 m ahead, seen by three rays.
        let readings: Vec<Reading> = [-0.05, 0.0, 0.05]
            .iter()
            .map(|&h: &f64| Reading {
                heading: h,
                range: 1.0 / h.cos(),
            })
            .collect();
        let d = free_distance(&readings, 0.0, 0.5, 5.0);
        assert!((d - 0.5).abs() < 1e-9, "{d}");
        // Driving away from it, nothing is in the way.
        assert_eq!(free_distance(&readings, PI, 0.5, 5.0), 5.0);
    }

    #[test]
    fn a_wall_beside_the_path_counts_when_the_body_would_touch_it() {
        // Near the left wall of the arena (x = -4), looking along it (+y): the readings
        // to the left are 0.3 m away, inside the half-width of 0.5 m.
        let readings = look_around(-3.7, 0.0, 4.0, 1.5, 0.04);
        let along_wall = free_distance(&readings, FRAC_PI_2, 0.5, 1.0);
        assert!(along_wall < 0.3, "{along_wall}");
        // Away from the wall, the drive may go as far as allowed.
        assert_eq!(free_distance(&readings, 0.0, 0.5, 0.9), 0.9);
    }

    #[test]
    fn the_choice_leaves_a_corner_and_never_ends_outside_the_arena() {
        for (x, y) in [(-3.5, -3.5), (3.4, 3.6), (0.0, 3.5), (1.0, -1.0)] {
            let readings = look_around(x, y, 4.0, 1.5, 0.048);
            let drive = choose(&readings, 0.55, 0.9);
            assert!(drive.distance > 0.3, "stuck at ({x}, {y}): {drive:?}");
            let (ex, ey) = (
                x + drive.distance * drive.heading.cos(),
                y + drive.distance * drive.heading.sin(),
            );
            // The body (0.15 m) ends clear of every wall.
            assert!(ex.abs() < 3.85 && ey.abs() < 3.85, "({ex}, {ey})");
        }
    }

    #[test]
    fn unseen_space_is_not_driven_into() {
        // Nothing within the sensor's 1.5 m anywhere: the drive still stops short of
        // what the rays saw.
        let readings = look_around(0.0, 0.0, 100.0, 1.5, 0.048);
        let drive = choose(&readings, 0.55, 5.0);
        assert!(drive.distance <= 1.5 - 0.55 + 1e-9, "{drive:?}");
    }

    #[test]
    fn a_goal_is_driven_to_in_pieces_and_then_stood_at() {
        let drive = toward((1.0, -1.0), (1.0, 2.0), 0.1, 2.0).unwrap();
        assert!((drive.heading + FRAC_PI_2).abs() < 1e-12, "{drive:?}");
        assert_eq!(drive.distance, 2.0);
        let drive = toward((1.0, -1.0), (0.0, -1.0), 0.1, 2.0).unwrap();
        assert_eq!((drive.heading, drive.distance), (0.0, 1.0));
        assert_eq!(toward((1.0, -1.0), (1.05, -0.95), 0.1, 2.0), None);
    }

    #[test]
    fn angles_wrap_into_one_turn() {
        assert!((wrap(3.0 * PI / 2.0) + FRAC_PI_2).abs() < 1e-12);
        assert!((wrap(-3.0 * PI / 2.0) - FRAC_PI_2).abs() < 1e-12);
        assert_eq!(wrap(0.25), 0.25);
    }
}
