//! Types for large values: camera images and point clouds, laid out as ROS 2's
//! `sensor_msgs/Image` and `sensor_msgs/PointCloud2` are (one flat byte buffer and the
//! numbers that say how to read it), so that a driver fills them with one copy and a
//! consumer reads pixels and points in place through the views below.
//!
//! Inside one process a value travels through the ports without a copy (a pooled
//! port hands out the same buffer to every reader). Across parts its bytes go as one
//! block (a length and the bytes, the postcard form of a `Vec<u8>`): encoded straight
//! into a shared-memory buffer when the parts share a computer (ferroc-zenoh's `shm`),
//! where the reader's `data` then stays, read in place ([`Bytes`]: no copy on either
//! side). Recordings store the same postcard form.
//!
//! A writer fills `data` through [`Bytes::to_mut`] (a `&mut Vec<u8>` that keeps its
//! allocation from one pooled value to the next).
//!
//! On a ROS 2 topic they are `sensor_msgs/msg/Image` and `sensor_msgs/msg/PointCloud2`
//! (`ros2.rs`; the manifest's `ros2=` lets check R102 accept them): the header filled
//! from the time of the sending step and the topic's `frame-id=`, a cloud as one row;
//! a sample these types cannot represent (big endian, data shorter than its rows,
//! padded cloud rows) is refused in words (docs/ros2.md, "Mapped types").

mod ros2;

pub use ferroc_runtime::module::Bytes;
use serde::{Deserialize, Serialize};

/// A camera image: `height` rows of `step` bytes each, pixels as `encoding` says.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Image {
    /// Pixels per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// How a pixel is stored, in ROS 2's names: `rgb8`, `bgr8`, `rgba8`, `mono8`,
    /// `mono16`, `16UC1`, `32FC1`, … ([`bytes_per_pixel`]).
    pub encoding: String,
    /// Bytes per row (at least `width` × bytes per pixel; more when rows are padded).
    pub step: u32,
    /// The rows, one after the other.
    pub data: Bytes,
}

ferroc_runtime::port_value!(Image, "ferroc_std.Image", pooled);

/// The bytes one pixel takes in the encoding `encoding` (ROS 2's names); `None` for
/// an encoding this table does not know.
pub fn bytes_per_pixel(encoding: &str) -> Option<u32> {
    Some(match encoding {
        "mono8" | "8UC1" | "8SC1" | "bayer_rggb8" | "bayer_bggr8" | "bayer_gbrg8"
        | "bayer_grbg8" => 1,
        "mono16" | "16UC1" | "16SC1" | "8UC2" => 2,
        "rgb8" | "bgr8" | "8UC3" => 3,
        "rgba8" | "bgra8" | "8UC4" | "32FC1" | "32SC1" | "16UC2" => 4,
        "rgb16" | "bgr16" | "16UC3" => 6,
        "rgba16" | "bgra16" | "16UC4" | "32FC2" | "64FC1" => 8,
        "32FC3" => 12,
        "32FC4" | "64FC2" => 16,
        _ => return None,
    })
}

impl Image {
    /// A black image of `width` × `height` pixels in `encoding`, rows unpadded; `None`
    /// for an encoding [`bytes_per_pixel`] does not know.
    pub fn new(width: u32, height: u32, encoding: &str) -> Option<Image> {
        let step = width.checked_mul(bytes_per_pixel(encoding)?)?;
        let len = usize::try_from(u64::from(step) * u64::from(height)).ok()?;
        Some(Image {
            width,
            height,
            encoding: encoding.to_owned(),
            step,
            data: vec![0; len].into(),
        })
    }

    /// Whether the numbers agree with the bytes: an error in plain words if a row is
    /// shorter than its pixels or the data shorter than its rows (a value from a
    /// driver or a peer with a bug).
    pub fn check(&self) -> Result<(), String> {
        if let Some(bpp) = bytes_per_pixel(&self.encoding) {
            let row = u64::from(self.width) * u64::from(bpp);
            if u64::from(self.step) < row {
                return Err(format!(
                    "a row of {} {} pixels needs {row} bytes, but step is {}",
                    self.width, self.encoding, self.step
                ));
            }
        }
        let need = u64::from(self.step) * u64::from(self.height);
        if (self.data.len() as u64) < need {
            return Err(format!(
                "{} rows of {} bytes need {need} bytes of data, but there are {}",
                self.height,
                self.step,
                self.data.len()
            ));
        }
        Ok(())
    }

    /// Row `y` (its `step` bytes, padding included), read in place; `None` past the
    /// last row or the data.
    pub fn row(&self, y: u32) -> Option<&[u8]> {
        let step = self.step as usize;
        let start = (y as usize).checked_mul(step)?;
        (y < self.height)
            .then(|| self.data.get(start..start + step))
            .flatten()
    }

    /// The bytes of pixel (`x`, `y`), read in place; `None` outside the image or for
    /// an unknown encoding.
    pub fn pixel(&self, x: u32, y: u32) -> Option<&[u8]> {
        let bpp = bytes_per_pixel(&self.encoding)? as usize;
        let start = (x as usize).checked_mul(bpp)?;
        (x < self.width)
            .then(|| self.row(y)?.get(start..start + bpp))
            .flatten()
    }
}

/// One field of the points of a [`PointCloud`] (ROS 2's `sensor_msgs/PointField`).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct PointField {
    /// `x`, `y`, `z`, `intensity`, `rgb`, …
    pub name: String,
    /// Where it starts in a point, in bytes.
    pub offset: u32,
    /// ROS 2's type code: 1 i8, 2 u8, 3 i16, 4 u16, 5 i32, 6 u32, 7 f32, 8 f64.
    pub datatype: u8,
    /// How many values of that type (1 for a scalar).
    pub count: u32,
}

/// The ROS 2 type code of `f32` fields.
pub const FLOAT32: u8 = 7;

/// A point cloud: points of `point_step` bytes each, one after the other, their
/// fields as `fields` say (little-endian).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct PointCloud {
    /// The fields of every point.
    pub fields: Vec<PointField>,
    /// Bytes per point.
    pub point_step: u32,
    /// The points.
    pub data: Bytes,
}

ferroc_runtime::port_value!(PointCloud, "ferroc_std.PointCloud", pooled);

impl PointCloud {
    /// A cloud of `x`, `y`, `z` (`f32`) points.
    pub fn xyz(points: &[[f32; 3]]) -> PointCloud {
        let fields = ["x", "y", "z"]
            .iter()
            .zip([0, 4, 8])
            .map(|(name, offset)| PointField {
                name: (*name).to_owned(),
                offset,
                datatype: FLOAT32,
                count: 1,
            })
            .collect();
        let data: Vec<u8> = points
            .iter()
            .flat_map(|p| p.iter().flat_map(|c| c.to_le_bytes()))
            .collect();
        PointCloud {
            fields,
            point_step: 12,
            data: data.into(),
        }
    }

    /// How many whole points the data holds.
    pub fn len(&self) -> usize {
        match self.point_step {
            0 => 0,
            step => self.data.len() / step as usize,
        }
    }

    /// Whether it holds no point.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Point `i`'s bytes, read in place.
    pub fn point(&self, i: usize) -> Option<&[u8]> {
        let step = self.point_step as usize;
        (i < self.len()).then(|| &self.data[i * step..(i + 1) * step])
    }

    /// The field named `name`.
    pub fn field(&self, name: &str) -> Option<&PointField> {
        self.fields.iter().find(|f| f.name == name)
    }

    /// The `f32` field `name` of point `i`; `None` if there is no such point, no such
    /// field, or the field is not an `f32` inside the point.
    pub fn f32_at(&self, i: usize, name: &str) -> Option<f32> {
        let field = self.field(name).filter(|f| f.datatype == FLOAT32)?;
        let start = field.offset as usize;
        let bytes = self.point(i)?.get(start..start + 4)?;
        Some(f32::from_le_bytes(bytes.try_into().ok()?))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_image_reads_rows_and_pixels_in_place() {
        let mut img = Image::new(4, 2, "rgb8").unwrap();
        assert_eq!((img.step, img.data.len()), (12, 24));
        img.data.to_mut()[12 + 3..12 + 6].copy_from_slice(&[1, 2, 3]);
        assert_eq!(img.pixel(1, 1), Some(&[1u8, 2, 3][..]));
        assert_eq!(img.row(1).map(<[u8]>::len), Some(12));
        assert_eq!(img.pixel(4, 0), None, "past the row");
        assert_eq!(img.row(2), None, "past the last row");
        assert!(img.check().is_ok());
        assert!(Image::new(4, 2, "no-such-encoding").is_none());
    }

    #[test]
    fn an_image_whose_numbers_disagree_with_its_bytes_is_refused_in_words() {
        let mut img = Image::new(4, 2, "rgb8").unwrap();
        img.data.to_mut().truncate(20);
        let err = img.check().unwrap_err();
        assert!(err.contains("24 bytes") && err.contains("20"), "{err}");
        img.step = 8;
        assert!(img.check().unwrap_err().contains("needs 12 bytes"));
        // Padded rows are fine, and so is a row of an unknown encoding.
        let mut padded = Image::new(4, 2, "mono8").unwrap();
        padded.step = 8;
        padded.data = vec![0; 16].into();
        assert!(padded.check().is_ok());
        assert_eq!(padded.pixel(3, 1), Some(&[0u8][..]));
    }

    #[test]
    fn the_wire_form_is_one_block_and_the_same_as_a_byte_vector() {
        let mut img = Image::new(3, 1, "mono8").unwrap();
        img.data = vec![9, 8, 7].into();
        let bytes = postcard::to_stdvec(&img).unwrap();
        let plain = postcard::to_stdvec(&(3u32, 1u32, "mono8", 3u32, vec![9u8, 8, 7])).unwrap();
        assert_eq!(bytes, plain);
        assert_eq!(postcard::from_bytes::<Image>(&bytes).unwrap(), img);
        let json = serde_json::to_string(&img).unwrap();
        assert_eq!(serde_json::from_str::<Image>(&json).unwrap(), img);
    }

    #[test]
    fn a_point_cloud_reads_its_fields_in_place() {
        let cloud = PointCloud::xyz(&[[1.0, 2.0, 3.0], [4.0, 5.0, 6.5]]);
        assert_eq!(cloud.len(), 2);
        assert_eq!(cloud.f32_at(1, "z"), Some(6.5));
        assert_eq!(cloud.f32_at(2, "z"), None, "no third point");
        assert_eq!(cloud.f32_at(0, "rgb"), None, "no such field");
        let bytes = postcard::to_stdvec(&cloud).unwrap();
        assert_eq!(postcard::from_bytes::<PointCloud>(&bytes).unwrap(), cloud);
        let empty = PointCloud::default();
        assert!(empty.is_empty() && empty.point(0).is_none());
    }
}
