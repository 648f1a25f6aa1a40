//! `rescue.Camera`: renders small grey-scale frames of the simulated building, and the
//! pinhole geometry the victim detector inverts.

use crate::hardware::{robot, Robot};
use crate::types::{Image, Pose2D};
use ferroc_runtime::module::{Module, ModuleType, Out, Parameter, Setup};
use std::time::Duration;

/// Frame width (pixels).
pub const WIDTH: u32 = 160;
/// Frame height (pixels).
pub const HEIGHT: u32 = 120;
/// Horizontal field of view: 60°.
pub const FIELD_OF_VIEW: f64 = std::f64::consts::FRAC_PI_3;
/// Height of the lens above the floor (m).
pub const LENS_HEIGHT: f64 = 1.0;
/// The camera looks down a little: the horizon is this pixel row, so most of the
/// frame shows the floor, where victims lie, down to 1.4 m in front of the lens.
pub const HORIZON: f64 = 20.0;
/// Victims lie on the floor: 0.5 m wide, 0.3 m tall.
const VICTIM_SIZE: (f64, f64) = (0.5, 0.3);
/// Victims are warm and bright: at least this value; walls and floor stay below.
pub const VICTIM_BRIGHTNESS: u8 = 128;
/// Victims farther than this are not rendered.
pub const CAMERA_RANGE: f64 = 9.6;

/// Focal length in pixels.
pub fn focal() -> f64 {
    f64::from(WIDTH) / 2.0 / (FIELD_OF_VIEW / 2.0).tan()
}

/// Bearing (rad, left positive) of the centre of pixel column `column`.
pub fn bearing_of_column(column: f64) -> f64 {
    ((f64::from(WIDTH) / 2.0 - column) / focal()).atan()
}

/// How clearly a victim at `distance` shows (0..1): fades with distance, and an
/// exposure shorter than 8 ms darkens it.
pub fn signal(distance: f64, exposure_ms: f64) -> f64 {
    (1.2 - distance / 8.0).clamp(0.0, 1.0) * (exposure_ms / 8.0).clamp(0.0, 1.0)
}

/// The frame the camera sees from `pose`.
pub fn render(robot: &Robot, pose: &Pose2D, exposure_ms: f64, stamp: Duration) -> Image {
    let (w, h) = (WIDTH as usize, HEIGHT as usize);
    let f = focal();
    let horizon = HORIZON;
    let mut pixels = vec![0u8; w * h];
    let mut wall_depth = vec![f64::INFINITY; w];
    for (c, depth) in wall_depth.iter_mut().enumerate() {
        let b = bearing_of_column(c as f64 + 0.5);
        let d = robot.world.ray((pose.x, pose.y), pose.theta + b, 30.0);
        *depth = d * b.cos();
        // Walls grey, darker far away; the floor below their foot dark.
        let foot = horizon + f * LENS_HEIGHT / depth.max(1e-3);
        let grey = (100.0 - 5.0 * d).clamp(40.0, 100.0) as u8;
        for r in 0..h {
            pixels[r * w + c] = if (r as f64 + 0.5) < foot { grey } else { 20 };
        }
    }
    for &(vx, vy) in &robot.world.victims {
        let (dx, dy) = (vx - pose.x, vy - pose.y);
        let distance = dx.hypot(dy);
        let b = crate::types::wrap_angle(dy.atan2(dx) - pose.theta);
        let depth = distance * b.cos();
        if depth < 0.3
            || distance > CAMERA_RANGE
            || b.abs() > FIELD_OF_VIEW / 2.0
            || !robot.world.line_of_sight((pose.x, pose.y), (vx, vy))
        {
            continue;
        }
        let centre = f64::from(WIDTH) / 2.0 - f * b.tan();
        let half = f * VICTIM_SIZE.0 / 2.0 / depth;
        let bottom = horizon + f * LENS_HEIGHT / depth;
        let top = horizon + f * (LENS_HEIGHT - VICTIM_SIZE.1) / depth;
        let value = f64::from(VICTIM_BRIGHTNESS) + 127.0 * signal(distance, exposure_ms);
        for (c, &wall) in wall_depth.iter().enumerate() {
            let x = c as f64 + 0.5;
            if (x - centre).abs() > half || wall < depth {
                continue;
            }
            for r in 0..h {
                let y = r as f64 + 0.5;
                if (top..bottom).contains(&y) {
                    pixels[r * w + c] = value as u8;
                }
            }
        }
    }
    Image {
        stamp,
        width: WIDTH,
        height: HEIGHT,
        pixels,
    }
}

/// Grabs a frame whenever a frame period of model time has passed.
pub struct Camera {
    image: Out<Image>,
    #[allow(dead_code)] // names the video device; the simulation needs none
    device: Parameter<String>,
    fps: Parameter<f64>,
    exposure: Parameter<f64>,
    /// Model time of the last frame.
    last: Option<Duration>,
}

impl ModuleType for Camera {
    const NAME: &'static str = "rescue.Camera";
    const DOC: &'static str = "USB camera grabber";

    fn create(m: &mut Setup<'_>) -> Self {
        Camera {
            image: m.output("image").build(),
            device: m.param("device").build(),
            fps: m
                .param("fps")
                .unit("Hz")
                .range(1.0, 60.0)
                .default(15.0)
                .build(),
            exposure: m
                .param("exposure")
                .unit("ms")
                .range(0.1, 100.0)
                .default(10.0)
                .build(),
            last: None,
        }
    }
}

impl Module for Camera {
    fn update(&mut self) {
        let robot = robot();
        let now = robot.time;
        let period = Duration::from_secs_f64(1.0 / self.fps.get().max(1.0));
        // The simulated clock moves in 25 ms steps: take the frame when it is due
        // within half a step.
        let due = self
            .last
            .is_none_or(|last| now + crate::hardware::PHYSICS_STEP / 2 >= last + period);
        if !due {
            return;
        }
        self.last = Some(now);
        let exposure = self.exposure.get();
        let pose = robot.pose;
        let frame = render(&robot, &pose, exposure, now);
        drop(robot);
        self.image.publish_with(|image| *image = frame);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::START;

    #[test]
    fn the_first_victim_is_in_the_frame_and_the_hidden_ones_are_not() {
        let robot = Robot::default();
        let frame = render(&robot, &robot.pose, 8.0, Duration::ZERO);
        assert_eq!(frame.pixels.len(), (WIDTH * HEIGHT) as usize);
        let bright: Vec<usize> = (0..frame.pixels.len())
            .filter(|&i| frame.pixels[i] >= VICTIM_BRIGHTNESS)
            .collect();
        assert!(!bright.is_empty());
        // The victim at (0, 1.2) is left of straight ahead: left half of the frame.
        let columns: Vec<usize> = bright.iter().map(|i| i % WIDTH as usize).collect();
        let mean = columns.iter().sum::<usize>() as f64 / columns.len() as f64;
        let expected = f64::from(WIDTH) / 2.0 - focal() * (1.2f64 / (0.0 - START.0));
        assert!((mean - expected).abs() < 1.5, "{mean} vs {expected}");
        // From the middle room looking east, the third victim is straight ahead
        // but behind the partition at x = 6: not in the frame.
        let mut middle = Robot::default();
        middle.pose = Pose2D {
            x: 4.0,
            y: 3.0,
            theta: 0.0,
        };
        let frame = render(&middle, &middle.pose, 8.0, Duration::ZERO);
        assert!(frame.pixels.iter().all(|&p| p < VICTIM_BRIGHTNESS));
    }

    #[test]
    fn the_signal_fades_with_distance_and_short_exposure() {
        assert_eq!(signal(1.0, 8.0), 1.0);
        assert!((signal(4.0, 8.0) - 0.7).abs() < 1e-12);
        assert_eq!(signal(4.0, 4.0), signal(4.0, 8.0) / 2.0);
        assert_eq!(signal(20.0, 8.0), 0.0);
    }
}
