//! `nav_behaviours.ArenaSimulation` (the crash-course arena with a pillar and a range
//! scanner) and `nav_behaviours.GoalServer`.

use crate::{Pose2D, RangeScan};
use ferroc_runtime::console;
use ferroc_runtime::module::{In, Kind, Module, ModuleType, Out, Parameter, Setup};

/// Simulated time per control step outside a periodic thread container (a test
/// calling the steps), as in the crash course (25 Hz).
pub const STEP_SECONDS: f64 = 0.04;

/// Simulated time per control step: the period of the thread container running the
/// step (`control`, 40 ms), else [`STEP_SECONDS`]; a fixed step, so a run is
/// reproducible cycle for cycle whatever the wall-clock timing.
pub fn step_seconds() -> f64 {
    ferroc_runtime::module::cycle::period().map_or(STEP_SECONDS, |p| p.as_secs_f64())
}
/// Distance from the robot's centre to its bumper.
pub const RADIUS: f64 = 0.15;

/// The arena's geometry at a moment (parameters may change while running).
#[derive(Clone, Copy, Debug)]
pub struct Arena {
    /// Half the side of the square arena.
    pub half: f64,
    /// Centre and radius of the pillar.
    pub pillar: (f64, f64, f64),
}

impl Arena {
    /// Distance from `(x, y)` along `heading` to the first wall or the pillar.
    pub fn ray(&self, x: f64, y: f64, heading: f64) -> f64 {
        let (dx, dy) = (heading.cos(), heading.sin());
        let along = |p: f64, d: f64| {
            if d > 1e-12 {
                (self.half - p) / d
            } else if d < -1e-12 {
                (-self.half - p) / d
            } else {
                f64::INFINITY
            }
        };
        let wall = along(x, dx).min(along(y, dy)).max(0.0);
        let (cx, cy, r) = self.pillar;
        let (fx, fy) = (x - cx, y - cy);
        let b = fx * dx + fy * dy;
        let c = fx * fx + fy * fy - r * r;
        let disc = b * b - c;
        let pillar = if r <= 0.0 || disc < 0.0 {
            f64::INFINITY
        } else if c <= 0.0 {
            0.0 // inside the pillar
        } else {
            let t = -b - disc.sqrt();
            if t >= 0.0 {
                t
            } else {
                f64::INFINITY
            }
        };
        wall.min(pillar)
    }

    /// Whether a robot centred at `(x, y)` touches nothing.
    pub fn free(&self, x: f64, y: f64) -> bool {
        let (cx, cy, r) = self.pillar;
        let inside = x.abs() <= self.half - RADIUS && y.abs() <= self.half - RADIUS;
        inside && (r <= 0.0 || (x - cx).hypot(y - cy) >= r + RADIUS)
    }
}

/// Kinematic simulation of a differential-drive robot with a range scanner.
pub struct ArenaSimulation {
    pose_out: Out<Pose2D>,
    scan: Out<RangeScan>,
    linear: In<f64>,
    angular: In<f64>,
    arena_size: Parameter<f64>,
    pillar_x: Parameter<f64>,
    pillar_y: Parameter<f64>,
    pillar_radius: Parameter<f64>,
    beams: Parameter<u32>,
    max_range: Parameter<f64>,
    pose: Pose2D,
    bumping: bool,
    bumps: u64,
}

impl ArenaSimulation {
    fn arena(&mut self) -> Arena {
        Arena {
            half: self.arena_size.get() / 2.0,
            pillar: (
                self.pillar_x.get(),
                self.pillar_y.get(),
                self.pillar_radius.get(),
            ),
        }
    }
}

impl ModuleType for ArenaSimulation {
    const NAME: &'static str = "nav_behaviours.ArenaSimulation";
    const KIND: Kind = Kind::SenseControl;
    const DOC: &'static str =
        "Kinematic simulation of a robot with a range scanner in the crash-course arena";

    fn create(m: &mut Setup<'_>) -> Self {
        let metres = |m: &mut Setup<'_>, name: &str, default: f64| -> Parameter<f64> {
            m.param(name).unit("m").default(default).build()
        };
        let mut start_x = metres(m, "start_x", 0.0);
        let mut start_y = metres(m, "start_y", 0.0);
        let mut start_theta: Parameter<f64> =
            m.param("start_theta").unit("rad").default(0.0).build();
        ArenaSimulation {
            pose_out: m.sensor_output("pose").build(),
            scan: m.sensor_output("scan").build(),
            linear: m.controller_input("linear").unit("m/s").build(),
            angular: m.controller_input("angular").unit("rad/s").build(),
            arena_size: m
                .param("arena_size")
                .unit("m")
                .range(1.0, 100.0)
                .default(8.0)
                .build(),
            pillar_x: metres(m, "pillar_x", 0.0),
            pillar_y: metres(m, "pillar_y", 0.0),
            pillar_radius: m
                .param("pillar_radius")
                .unit("m")
                .range(0.0, 10.0)
                .default(0.6)
                .build(),
            beams: m.param("beams").range(4.0, 720.0).default(72).build(),
            max_range: m
                .param("max_range")
                .unit("m")
                .range(0.1, 30.0)
                .default(4.0)
                .build(),
            pose: Pose2D {
                x: start_x.get(),
                y: start_y.get(),
                theta: start_theta.get(),
            },
            bumping: false,
            bumps: 0,
        }
    }
}

impl Module for ArenaSimulation {
    fn sense(&mut self) {
        let arena = self.arena();
        let beams = self.beams.get().max(1) as usize;
        let max_range = self.max_range.get();
        let Pose2D { x, y, theta } = self.pose;
        let increment = std::f64::consts::TAU / beams as f64;
        let angle_min = -std::f64::consts::PI;
        self.scan.publish_with(|scan| {
            scan.ranges.resize(beams, 0.0);
            scan.angle_min = angle_min;
            scan.angle_increment = increment;
            scan.max_range = max_range;
            for (i, r) in scan.ranges.iter_mut().enumerate() {
                let along = arena.ray(x, y, theta + angle_min + i as f64 * increment);
                *r = (along - RADIUS).clamp(0.0, max_range);
            }
        });
        self.pose_out.publish(self.pose);
    }

    fn control(&mut self) {
        let arena = self.arena();
        let (v, w) = (self.linear.get(), self.angular.get());
        let (v, w) = (
            if v.is_finite() { v } else { 0.0 },
            if w.is_finite() { w } else { 0.0 },
        );
        let dt = step_seconds();
        let theta = crate::wrap(self.pose.theta + w * dt);
        let x = self.pose.x + v * theta.cos() * dt;
        let y = self.pose.y + v * theta.sin() * dt;
        self.pose.theta = theta;
        if arena.free(x, y) {
            self.pose.x = x;
            self.pose.y = y;
            self.bumping = false;
        } else if !self.bumping {
            self.bumping = true;
            self.bumps += 1;
            console::line(&format!(
                "[sim] bump {}: the robot touched an obstacle at x={:+.2} m y={:+.2} m",
                self.bumps, self.pose.x, self.pose.y
            ));
        }
    }
}

/// `nav_behaviours.GoalServer`: publishes the goal set by its parameters.
pub struct GoalServer {
    goal: Out<Pose2D>,
    x: Parameter<f64>,
    y: Parameter<f64>,
}

impl ModuleType for GoalServer {
    const NAME: &'static str = "nav_behaviours.GoalServer";
    const DOC: &'static str = "The current navigation goal, as set by the operator";
    fn create(m: &mut Setup<'_>) -> Self {
        GoalServer {
            goal: m.output("goal").build(),
            x: m.param("x").unit("m").default(0.0).build(),
            y: m.param("y").unit("m").default(0.0).build(),
        }
    }
}

impl Module for GoalServer {
    fn update(&mut self) {
        self.goal.publish(Pose2D {
            x: self.x.get(),
            y: self.y.get(),
            theta: 0.0,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rays_hit_walls_and_the_pillar() {
        let arena = Arena {
            half: 4.0,
            pillar: (2.0, 0.0, 0.5),
        };
        assert!((arena.ray(0.0, 0.0, 0.0) - 1.5).abs() < 1e-12);
        assert!((arena.ray(0.0, 0.0, std::f64::consts::PI) - 4.0).abs() < 1e-12);
        assert!((arena.ray(0.0, 0.0, std::f64::consts::FRAC_PI_2) - 4.0).abs() < 1e-12);
        assert!(arena.free(0.0, 0.0));
        assert!(!arena.free(1.4, 0.0));
        assert!(!arena.free(3.9, 0.0));
    }
}
