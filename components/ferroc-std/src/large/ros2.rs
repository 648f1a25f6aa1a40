//! [`Image`] as ROS 2's `sensor_msgs/msg/Image` and [`PointCloud`] as
//! `sensor_msgs/msg/PointCloud2` (docs/ros2.md, "Mapped types"): the manifest says
//! `ros2="…"` on both `<type>`s, so check R102 accepts them on those messages, and the
//! ROS 2 ends (the wire, `--record`'s ROS 2 channels, `Player`) write and read them
//! here.
//!
//! The message's fields the types do not have are filled truthfully: `header.stamp` is
//! when the step that sends the value ran (model time in lockstep), `header.frame_id`
//! the topic's `frame-id=` (default `""`), `is_bigendian` 0 (ferroc's values are little
//! endian). A point cloud is one row: `height` 1, `width` its points, `row_step` its
//! bytes; `is_dense` false (ROS 2's "may hold invalid points": always true of it, so a
//! reader checks each point, as it must for most sensors' clouds anyway).
//!
//! The byte block goes in bulk, one copy into the sample (and one out of it on the way
//! in), as CDR needs. Reading refuses in words what the types cannot represent: big
//! endian data (of more than one byte per channel), rows or data shorter than the
//! numbers say, a cloud whose rows are padded.

use super::{bytes_per_pixel, Bytes, Image, PointCloud, PointField};
use ferroc_ros2::serde_cdr::{self, Shape};
use ferroc_runtime::module::{Ros2Message, Ros2Meta, Timestamp};
use serde::{Deserialize, Serialize, Serializer};

/// `builtin_interfaces/msg/Time`.
#[derive(Serialize, Deserialize)]
struct Time {
    sec: i32,
    nanosec: u32,
}

impl Time {
    /// ROS 2's time of `t`: whole seconds (saturating at `int32`'s range) and
    /// nanoseconds.
    fn of(t: Timestamp) -> Time {
        let sec = t.nanos.div_euclid(1_000_000_000);
        Time {
            sec: i32::try_from(sec).unwrap_or(if sec < 0 { i32::MIN } else { i32::MAX }),
            nanosec: t.nanos.rem_euclid(1_000_000_000) as u32,
        }
    }
}

/// `std_msgs/msg/Header` on the way out.
#[derive(Serialize)]
struct HeaderOut<'a> {
    stamp: Time,
    frame_id: &'a str,
}

impl<'a> HeaderOut<'a> {
    fn of(meta: &Ros2Meta<'a>) -> Self {
        HeaderOut {
            stamp: Time::of(meta.stamp),
            frame_id: meta.frame_id,
        }
    }
}

/// `std_msgs/msg/Header` on the way in (read, then left: the types have no place for it).
#[derive(Deserialize)]
struct HeaderIn {
    #[allow(dead_code)] // read to consume its bytes
    stamp: Time,
    #[allow(dead_code)]
    frame_id: String,
}

/// A `uint8[]` written in one block (serde writes a plain `&[u8]` element by element).
struct Block<'a>(&'a [u8]);

impl Serialize for Block<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_bytes(self.0)
    }
}

#[derive(Serialize)]
struct ImageOut<'a> {
    header: HeaderOut<'a>,
    height: u32,
    width: u32,
    encoding: &'a str,
    is_bigendian: u8,
    step: u32,
    data: Block<'a>,
}

#[derive(Deserialize)]
struct ImageIn {
    #[allow(dead_code)]
    header: HeaderIn,
    height: u32,
    width: u32,
    encoding: String,
    is_bigendian: u8,
    step: u32,
    data: Bytes,
}

impl Ros2Message for Image {
    const MESSAGE: &'static str = "sensor_msgs/msg/Image";

    fn to_cdr(
        &self,
        shape: &Shape<'_>,
        meta: &Ros2Meta<'_>,
        buf: &mut Vec<u8>,
    ) -> Result<(), String> {
        self.check()?;
        // `check` made sure the rows fit in the data; a longer block is cut to them, as
        // ROS 2 readers expect `step × height` bytes exactly.
        let rows = (self.step as usize) * (self.height as usize);
        let message = ImageOut {
            header: HeaderOut::of(meta),
            height: self.height,
            width: self.width,
            encoding: &self.encoding,
            is_bigendian: 0,
            step: self.step,
            data: Block(&self.data[..rows]),
        };
        serde_cdr::to_cdr(shape, &message, buf).map_err(|e| e.to_string())
    }

    fn from_cdr(shape: &Shape<'_>, bytes: &[u8]) -> Result<Image, String> {
        let m: ImageIn = serde_cdr::from_cdr(shape, bytes).map_err(|e| e.to_string())?;
        if m.is_bigendian != 0 && !single_byte_channels(&m.encoding) {
            return Err(format!(
                "a big-endian `{}` image cannot be represented (ferroc_std.Image is little \
                 endian)",
                m.encoding
            ));
        }
        let image = Image {
            width: m.width,
            height: m.height,
            encoding: m.encoding,
            step: m.step,
            data: m.data,
        };
        image.check()?;
        Ok(image)
    }
}

/// Whether every channel of a pixel in `encoding` is one byte (its byte order then
/// says nothing); `false` for an encoding [`bytes_per_pixel`] does not know.
fn single_byte_channels(encoding: &str) -> bool {
    let channels = match encoding {
        "rgb8" | "bgr8" | "8UC3" | "8SC3" => 3,
        "rgba8" | "bgra8" | "8UC4" | "8SC4" => 4,
        "8UC2" | "8SC2" => 2,
        _ => 1,
    };
    bytes_per_pixel(encoding).is_some_and(|b| b == channels)
}

#[derive(Serialize)]
struct CloudOut<'a> {
    header: HeaderOut<'a>,
    height: u32,
    width: u32,
    fields: &'a [PointField],
    is_bigendian: bool,
    point_step: u32,
    row_step: u32,
    data: Block<'a>,
    is_dense: bool,
}

#[derive(Deserialize)]
struct CloudIn {
    #[allow(dead_code)]
    header: HeaderIn,
    height: u32,
    width: u32,
    fields: Vec<PointField>,
    is_bigendian: bool,
    point_step: u32,
    row_step: u32,
    data: Bytes,
    #[allow(dead_code)] // nothing in a PointCloud says it
    is_dense: bool,
}

impl Ros2Message for PointCloud {
    const MESSAGE: &'static str = "sensor_msgs/msg/PointCloud2";

    fn to_cdr(
        &self,
        shape: &Shape<'_>,
        meta: &Ros2Meta<'_>,
        buf: &mut Vec<u8>,
    ) -> Result<(), String> {
        let bytes = self.data.len();
        let whole = match self.point_step {
            0 => bytes == 0,
            step => bytes % step as usize == 0,
        };
        let (Ok(width), Ok(row_step), true) =
            (u32::try_from(self.len()), u32::try_from(bytes), whole)
        else {
            return Err(format!(
                "{bytes} bytes of data are not a whole number of points of {} bytes",
                self.point_step
            ));
        };
        let message = CloudOut {
            header: HeaderOut::of(meta),
            height: 1,
            width,
            fields: &self.fields,
            is_bigendian: false,
            point_step: self.point_step,
            row_step,
            data: Block(&self.data),
            is_dense: false,
        };
        serde_cdr::to_cdr(shape, &message, buf).map_err(|e| e.to_string())
    }

    fn from_cdr(shape: &Shape<'_>, bytes: &[u8]) -> Result<PointCloud, String> {
        let m: CloudIn = serde_cdr::from_cdr(shape, bytes).map_err(|e| e.to_string())?;
        if m.is_bigendian {
            return Err(
                "a big-endian point cloud cannot be represented (ferroc_std.PointCloud \
                        is little endian)"
                    .into(),
            );
        }
        let row = u64::from(m.width) * u64::from(m.point_step);
        if u64::from(m.row_step) != row {
            return Err(format!(
                "rows of {} bytes hold {} points of {} bytes: a PointCloud cannot represent \
                 padded rows",
                m.row_step, m.width, m.point_step
            ));
        }
        let need = row * u64::from(m.height);
        if m.data.len() as u64 != need {
            return Err(format!(
                "{} rows of {} bytes need {need} bytes of data, but there are {}",
                m.height,
                m.row_step,
                m.data.len()
            ));
        }
        Ok(PointCloud {
            fields: m.fields,
            point_step: m.point_step,
            data: m.data,
        })
    }
}

#[cfg(test)]
#[path = "ros2_tests.rs"]
mod tests;
