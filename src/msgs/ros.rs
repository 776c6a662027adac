//! The ROS 2 messages the bridge and a replay read, as decoded from CDR ([`super::cdr`])
//! with their bytes borrowed, and their conversion to the packed RGB frames perception
//! takes.

use super::pixels::{PixelError, rgb_from_compressed, rgb_from_raw};
use crate::geometry::{Pose2, Twist};
use crate::perception::RgbImage;

/// `builtin_interfaces/msg/Time`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Time {
    /// Seconds (since the epoch, or since boot on some drivers).
    pub sec: i32,
    /// Nanoseconds within the second.
    pub nanosec: u32,
}

impl Time {
    /// The stamp in nanoseconds, or `None` for a zero or negative stamp (a driver that
    /// does not stamp), so the caller falls back to the log time.
    pub fn ns(&self) -> Option<u64> {
        let ns = i64::from(self.sec) * 1_000_000_000 + i64::from(self.nanosec);
        u64::try_from(ns).ok().filter(|&n| n > 0)
    }
}

/// `std_msgs/msg/Header`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Header<'a> {
    /// Capture time.
    pub stamp: Time,
    /// The sensor's frame.
    pub frame_id: &'a str,
}

/// `sensor_msgs/msg/Image`, pixels borrowed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Image<'a> {
    /// Stamp and frame.
    pub header: Header<'a>,
    /// Rows.
    pub height: u32,
    /// Columns.
    pub width: u32,
    /// Pixel encoding (`rgb8`, `bgr8`, `mono8`, `bayer_rggb8`, `16UC1` …).
    pub encoding: &'a str,
    /// 1 when multi-byte channels are big-endian.
    pub is_bigendian: u8,
    /// Bytes per row.
    pub step: u32,
    /// `step · height` bytes of pixels.
    pub data: &'a [u8],
}

impl Image<'_> {
    /// The frame as packed RGB8.
    ///
    /// # Errors
    /// [`PixelError`] for an encoding perception cannot use (16-bit depth, 16-bit mosaics,
    /// floats …) or sizes that do not add up.
    pub fn to_rgb(&self) -> Result<RgbImage, PixelError> {
        rgb_from_raw(self.width, self.height, self.encoding, self.step, self.data)
    }
}

/// `sensor_msgs/msg/CompressedImage`, bytes borrowed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CompressedImage<'a> {
    /// Stamp and frame.
    pub header: Header<'a>,
    /// `jpeg`, `png`, or image_transport's `rgb8; jpeg compressed bgr8` style.
    pub format: &'a str,
    /// The compressed file's bytes.
    pub data: &'a [u8],
}

impl CompressedImage<'_> {
    /// The frame as packed RGB8.
    ///
    /// # Errors
    /// [`PixelError`] for depth formats, 16-bit images, or bytes that do not decode.
    pub fn to_rgb(&self) -> Result<RgbImage, PixelError> {
        rgb_from_compressed(self.format, self.data)
    }
}

/// `nav_msgs/msg/Odometry`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Odometry<'a> {
    /// Stamp and the pose's frame (`odom`).
    pub header: Header<'a>,
    /// The body frame the twist is in (`base_link`).
    pub child_frame_id: &'a str,
    /// Position x, y, z, m.
    pub position: [f64; 3],
    /// Orientation quaternion x, y, z, w.
    pub orientation: [f64; 4],
    /// Row-major 6×6 pose covariance.
    pub pose_covariance: [f64; 36],
    /// Linear velocity x, y, z, m/s, body frame.
    pub linear: [f64; 3],
    /// Angular velocity x, y, z, rad/s, body frame.
    pub angular: [f64; 3],
    /// Row-major 6×6 twist covariance.
    pub twist_covariance: [f64; 36],
}

/// Heading (yaw about +z, counter-clockwise, radians) of the quaternion (x, y, z, w).
pub fn yaw_of(q: [f64; 4]) -> f64 {
    let [x, y, z, w] = q;
    (2.0 * (w * z + x * y)).atan2(1.0 - 2.0 * (y * y + z * z))
}

impl Odometry<'_> {
    /// The planar pose (x, y, yaw) in the odometry frame.
    pub fn pose2(&self) -> Pose2 {
        Pose2::new(self.position[0], self.position[1], yaw_of(self.orientation))
    }

    /// The planar body twist (forward speed, yaw rate).
    pub fn twist(&self) -> Twist {
        Twist::new(self.linear[0], self.angular[2])
    }
}
