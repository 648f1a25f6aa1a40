//! `warehouse.SafetyScanner`: a safety laser scanner on the front bumper, simulated.
//!
//! The scanner has no pose input (the real one knows nothing of the map either), so the
//! simulation is a scene in the scanner's own frame: open floor, and now and then a
//! person walking across the path ahead. Fixed structure such as racks is left out on
//! purpose: without the robot's pose it could not turn as the robot turns, and a
//! localizer matching walls in the scan (`rescue.Localizer`) would then hold the
//! heading still while the robot turns. For the same reason a beam without return reads
//! as infinite rather than the maximum range: a ring of maximum-range points looks like
//! a wall to such a localizer. When and how close people cross follows a
//! fixed-seed sequence keyed by the scanner's address, so each robot sees its own,
//! reproducible traffic.

use crate::sequence::Sequence;
use crate::timing::IO_STEP;
use crate::LaserScan;
use ferroc_runtime::module::{Module, ModuleType, Out, Parameter, Setup};
use std::f64::consts::PI;

/// First beam, relative to straight ahead (a 270° scanner).
const ANGLE_MIN: f64 = -0.75 * PI;
/// Beams of one sweep (1° apart).
const BEAMS: usize = 271;
/// Nothing farther away is reported.
const MAX_RANGE: f64 = 10.0;
/// The fields watch the driving direction: beams within this angle of straight ahead.
const FIELD_HALF_ANGLE: f64 = PI / 4.0;
/// A person, seen from above: a circle of this radius, walking at this speed (m/s).
const PERSON_RADIUS: f64 = 0.25;
const WALKING_SPEED: f64 = 1.0;

/// The scene in the scanner's frame (x ahead, y left) at one moment.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AisleScene {
    /// Where a person crossing the aisle stands, if one does.
    pub person: Option<(f64, f64)>,
}

impl AisleScene {
    /// Distance along the beam at `angle` (0: straight ahead) to the first surface;
    /// infinite when nothing is within range (no return, as ROS REP 117 reports it).
    pub fn ray(&self, angle: f64) -> f64 {
        let (dx, dy) = (angle.cos(), angle.sin());
        let person = self.person.map_or(f64::INFINITY, |(px, py)| {
            // Ray-circle intersection: |t·d − p|² = r².
            let b = px * dx + py * dy;
            let c = px * px + py * py - PERSON_RADIUS * PERSON_RADIUS;
            let disc = b * b - c;
            if c <= 0.0 {
                0.0
            } else if disc < 0.0 || b - disc.sqrt() < 0.0 {
                f64::INFINITY
            } else {
                b - disc.sqrt()
            }
        });
        if person <= MAX_RANGE {
            person
        } else {
            f64::INFINITY
        }
    }

    /// The whole sweep, beam `i` at `ANGLE_MIN + i · 1°`.
    pub fn sweep(&self, ranges: &mut Vec<f32>) {
        ranges.clear();
        ranges.extend((0..BEAMS).map(|i| self.ray(beam_angle(i)) as f32));
    }
}

fn beam_angle(i: usize) -> f64 {
    ANGLE_MIN + i as f64 * (PI / 180.0)
}

/// Whether anything is closer than `distance` in the field ahead.
pub fn field_violated(ranges: &[f32], distance: f64) -> bool {
    ranges
        .iter()
        .enumerate()
        .any(|(i, r)| beam_angle(i).abs() <= FIELD_HALF_ANGLE && f64::from(*r) < distance)
}

/// One person crossing: starts at `start` seconds, `ahead` metres in front.
#[derive(Clone, Copy, Debug)]
struct Crossing {
    start: f64,
    ahead: f64,
}

/// The safety scanner, with protective and warning fields ahead.
pub struct SafetyScanner {
    scan: Out<LaserScan>,
    protective_stop: Out<bool>,
    warning_field: Out<bool>,
    ip: Parameter<String>,
    protective_field: Parameter<f64>,
    warning_distance: Parameter<f64>,
    traffic: Option<Sequence>,
    crossing: Option<Crossing>,
    time: f64,
}

impl SafetyScanner {
    /// The scene now; schedules the next crossing when the last one is over.
    fn scene(&mut self) -> AisleScene {
        let ip = &mut self.ip;
        let traffic = self
            .traffic
            .get_or_insert_with(|| Sequence::from_text(ip.value()));
        let crossing = *self.crossing.get_or_insert_with(|| Crossing {
            start: traffic.between(8.0, 20.0),
            ahead: traffic.between(0.3, 1.4),
        });
        // The person walks from 2 m right to 2 m left of the robot's path.
        let walked = (self.time - crossing.start) * WALKING_SPEED;
        if walked < 0.0 {
            return AisleScene::default();
        }
        if walked > 4.0 {
            self.crossing = Some(Crossing {
                start: self.time + traffic.between(15.0, 40.0),
                ahead: traffic.between(0.3, 1.4),
            });
            return AisleScene::default();
        }
        AisleScene {
            person: Some((crossing.ahead, walked - 2.0)),
        }
    }
}

impl ModuleType for SafetyScanner {
    const NAME: &'static str = "warehouse.SafetyScanner";
    const DOC: &'static str =
        "Certified safety laser scanner (Ethernet) with protective and warning fields";

    fn create(m: &mut Setup<'_>) -> Self {
        SafetyScanner {
            scan: m.output("scan").build(),
            protective_stop: m
                .output("protective_stop")
                .doc("protective field violated: the drive must stop")
                .build(),
            warning_field: m.output("warning_field").build(),
            ip: m.param("ip").build(),
            protective_field: m
                .param("protective_field")
                .unit("m")
                .range(0.1, 5.0)
                .default(0.5)
                .build(),
            warning_distance: m
                .param("warning_field")
                .unit("m")
                .range(0.1, 10.0)
                .default(1.5)
                .build(),
            traffic: None,
            crossing: None,
            time: 0.0,
        }
    }
}

impl Module for SafetyScanner {
    fn update(&mut self) {
        let scene = self.scene();
        self.time += IO_STEP;
        let (protective, warning) = (self.protective_field.get(), self.warning_distance.get());
        let mut violated = (false, false);
        self.scan.publish_with(|scan| {
            scan.angle_min = ANGLE_MIN;
            scan.angle_increment = PI / 180.0;
            scene.sweep(&mut scan.ranges);
            scan.intensities.clear();
            scan.intensities.resize(scan.ranges.len(), 1.0);
            violated = (
                field_violated(&scan.ranges, protective),
                field_violated(&scan.ranges, warning),
            );
        });
        self.protective_stop.publish(violated.0);
        self.warning_field.publish(violated.1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ranges(scene: AisleScene) -> Vec<f32> {
        let mut r = Vec::new();
        scene.sweep(&mut r);
        r
    }

    #[test]
    fn open_floor_violates_no_field() {
        let r = ranges(AisleScene::default());
        assert_eq!(r.len(), BEAMS);
        assert!(
            r.iter().all(|x| x.is_infinite()),
            "no return reads as infinite"
        );
        assert!(!field_violated(&r, 0.45));
        assert!(!field_violated(&r, 1.5));
    }

    #[test]
    fn a_person_ahead_is_seen_and_one_behind_is_not_in_the_fields() {
        let ahead = AisleScene {
            person: Some((0.6, 0.0)),
        };
        assert!((ahead.ray(0.0) - 0.35).abs() < 1e-9);
        let r = ranges(ahead);
        assert!(field_violated(&r, 0.45));
        assert!(field_violated(&r, 1.5));
        assert!(!field_violated(&r, 0.3));
        // Behind the scanner (outside its 270°, and outside the fields anyway).
        let behind = AisleScene {
            person: Some((-0.6, 0.0)),
        };
        assert_eq!(behind.ray(0.0), f64::INFINITY);
        let r = ranges(behind);
        assert!(!field_violated(&r, 0.45) && !field_violated(&r, 1.5));
        // Beside the robot: in the scan, not in the fields ahead.
        let beside = AisleScene {
            person: Some((0.0, 0.6)),
        };
        assert!((beside.ray(PI / 2.0) - 0.35).abs() < 1e-9);
        assert!(!field_violated(&ranges(beside), 0.45));
    }
}
