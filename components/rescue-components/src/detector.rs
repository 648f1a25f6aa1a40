//! `rescue.VictimDetector`: finds the bright blobs victims make in camera frames, places
//! them on the map and keeps the list of victims found.

use crate::camera::{bearing_of_column, focal, HORIZON, LENS_HEIGHT, VICTIM_BRIGHTNESS};
use crate::types::{Image, LaserScan, Pose2D, Victim, VictimList};
use ferroc_runtime::module::{In, Module, ModuleType, Out, Parameter, Setup};

/// One victim seen in one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Detection {
    /// Bearing from the camera, left positive (rad).
    pub bearing: f64,
    /// Distance from the camera (m).
    pub distance: f64,
    /// 0..1, from the blob's brightness.
    pub confidence: f64,
}

/// The victims in a frame: runs of columns holding victim-bright pixels, placed by the
/// ground-plane geometry (the lower a victim's foot in the frame, the closer it is).
pub fn detect(image: &Image) -> Vec<Detection> {
    let (w, h) = (image.width as usize, image.height as usize);
    if w == 0 || h == 0 || image.pixels.len() != w * h {
        return Vec::new(); // not a frame this detector understands
    }
    let horizon = HORIZON;
    let mut found = Vec::new();
    // (first column, foot row, brightness sum, bright pixel count) of the open blob.
    let mut open: Option<(usize, usize, u64, u64)> = None;
    for c in 0..=w {
        let column = (c < w).then(|| {
            (0..h)
                .filter(|r| image.pixels[r * w + c] >= VICTIM_BRIGHTNESS)
                .fold(None, |acc: Option<(usize, u64, u64)>, r| {
                    let v = u64::from(image.pixels[r * w + c]);
                    let (foot, sum, n) = acc.unwrap_or((0, 0, 0));
                    Some((foot.max(r + 1), sum + v, n + 1))
                })
        });
        match (column.flatten(), open.as_mut()) {
            (Some((foot, sum, n)), Some(blob)) => {
                blob.1 = blob.1.max(foot);
                blob.2 += sum;
                blob.3 += n;
            }
            (Some((foot, sum, n)), None) => open = Some((c, foot, sum, n)),
            (None, _) => {
                if let Some((first, foot, sum, n)) = open.take() {
                    let below = foot as f64 - horizon;
                    // A foot at or above the horizon is not on the floor; one at the
                    // bottom edge may lie below the frame: its distance is unknown.
                    if below <= 0.0 || n == 0 || foot >= h {
                        continue;
                    }
                    let centre = (first + c) as f64 / 2.0;
                    let bearing = bearing_of_column(centre);
                    let depth = focal() * LENS_HEIGHT / below;
                    let mean = sum as f64 / n as f64;
                    found.push(Detection {
                        bearing,
                        distance: depth / bearing.cos(),
                        confidence: ((mean - f64::from(VICTIM_BRIGHTNESS)) / 127.0).clamp(0.0, 1.0),
                    });
                }
            }
        }
    }
    found
}

/// The victims found so far, merged by distance.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VictimBook {
    /// In the order found; ids count from 1.
    pub victims: Vec<Victim>,
}

impl VictimBook {
    /// Adds a detection at map position (x, y), or improves the victim within
    /// `merge_distance`: a more confident detection was taken closer, so its position
    /// replaces the old one. True if the list changed.
    pub fn add(&mut self, x: f64, y: f64, confidence: f64, merge_distance: f64) -> bool {
        let confidence = confidence as f32;
        let near = self
            .victims
            .iter_mut()
            .find(|v| (v.x - x).hypot(v.y - y) <= merge_distance);
        match near {
            Some(v) if confidence > v.confidence => {
                (v.x, v.y, v.confidence) = (x, y, confidence);
                true
            }
            Some(_) => false,
            None => {
                let id = self.victims.len() as u32 + 1;
                self.victims.push(Victim {
                    x,
                    y,
                    id,
                    confidence,
                });
                true
            }
        }
    }
}

/// Detects victims in each new frame and publishes the list when it changes.
pub struct VictimDetector {
    image: In<Image>,
    pose: In<Pose2D>,
    scan: In<LaserScan>,
    victims: Out<VictimList>,
    victim_count: Out<u32>,
    #[allow(dead_code)] // the simulated camera needs no learned weights
    model_file: Parameter<String>,
    threshold: Parameter<f64>,
    merge_distance: Parameter<f64>,
    book: VictimBook,
}

impl ModuleType for VictimDetector {
    const NAME: &'static str = "rescue.VictimDetector";
    const DOC: &'static str = "Detects victims in camera images and places them in the map";

    fn create(m: &mut Setup<'_>) -> Self {
        VictimDetector {
            image: m.input("image").required().build(),
            pose: m.input("pose").required().build(),
            scan: m
                .input("scan")
                .doc("used to estimate the distance of a detection")
                .build(),
            victims: m.output("victims").build(),
            victim_count: m.output("victim_count").build(),
            model_file: m
                .param("model_file")
                .doc("path of the detector weights")
                .build(),
            threshold: m
                .param("threshold")
                .range(0.0, 1.0)
                .default(0.7)
                .doc("minimum detection confidence; driven by the mission context")
                .build(),
            merge_distance: m
                .param("merge_distance")
                .unit("m")
                .range(0.0, 5.0)
                .default(0.5)
                .doc("detections closer than this are the same victim")
                .build(),
            book: VictimBook::default(),
        }
    }
}

impl Module for VictimDetector {
    fn update(&mut self) {
        let Some(image) = self.image.try_pop() else {
            return; // woken by a pose or scan: no new frame to look at
        };
        let pose = self.pose.get();
        let scan = self.scan.get();
        let (threshold, merge) = (self.threshold.get(), self.merge_distance.get());
        let mut changed = false;
        for d in detect(&image) {
            if d.confidence < threshold {
                continue;
            }
            // The laser sweeps above the victims and hits the wall behind them: a
            // detection beyond that wall is a reflection, not a victim.
            if scan
                .range_at(d.bearing)
                .is_some_and(|wall| d.distance > wall + 0.5)
            {
                continue;
            }
            let heading = pose.theta + d.bearing;
            let (x, y) = (
                pose.x + d.distance * heading.cos(),
                pose.y + d.distance * heading.sin(),
            );
            changed |= self.book.add(x, y, d.confidence, merge);
        }
        if changed {
            let stamp = image.stamp;
            let victims = &self.book.victims;
            self.victims.publish_with(|list| {
                list.stamp = stamp;
                list.victims.clone_from(victims);
            });
            self.victim_count.publish(victims.len() as u32);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::render;
    use crate::hardware::Robot;
    use std::time::Duration;

    #[test]
    fn a_victim_in_view_is_found_where_it_lies() {
        let robot = Robot::default();
        let frame = render(&robot, &robot.pose, 8.0, Duration::ZERO);
        let found = detect(&frame);
        assert_eq!(found.len(), 1, "{found:?}");
        let d = found[0];
        let (vx, vy) = robot.world.victims[0];
        let p = robot.pose;
        let (x, y) = (
            p.x + d.distance * (p.theta + d.bearing).cos(),
            p.y + d.distance * (p.theta + d.bearing).sin(),
        );
        // 4.2 m away: within a quarter metre (one pixel row is ~0.13 m there).
        assert!((x - vx).hypot(y - vy) < 0.25, "({x}, {y}) vs ({vx}, {vy})");
        assert!(
            (d.confidence - crate::camera::signal(4.18, 8.0)).abs() < 0.05,
            "{d:?}"
        );
    }

    #[test]
    fn a_victim_behind_a_wall_is_not_found() {
        let mut robot = Robot::default();
        robot.pose = Pose2D {
            x: 4.0,
            y: 3.0,
            theta: 0.0,
        };
        assert!(detect(&render(&robot, &robot.pose, 8.0, Duration::ZERO)).is_empty());
        // Turned south it sees the second victim, round the partition's gap.
        robot.pose.theta = -std::f64::consts::FRAC_PI_2;
        assert_eq!(
            detect(&render(&robot, &robot.pose, 8.0, Duration::ZERO)).len(),
            1
        );
    }

    #[test]
    fn malformed_frames_give_no_detections() {
        let bad = Image {
            stamp: Duration::ZERO,
            width: 10,
            height: 10,
            pixels: vec![255; 7],
        };
        assert!(detect(&bad).is_empty());
        assert!(detect(&Image::default()).is_empty());
    }

    #[test]
    fn close_detections_merge_and_the_more_confident_position_wins() {
        let mut book = VictimBook::default();
        assert!(book.add(1.0, 1.0, 0.7, 0.4));
        assert!(!book.add(1.2, 1.0, 0.6, 0.4)); // same victim, less sure: kept
        assert!(book.add(1.1, 1.1, 0.9, 0.4)); // same victim, surer: moved
        assert!(book.add(3.0, 1.0, 0.8, 0.4)); // another one
        assert_eq!(book.victims.len(), 2);
        assert_eq!((book.victims[0].x, book.victims[0].id), (1.1, 1));
        assert_eq!(book.victims[1].id, 2);
    }
}
