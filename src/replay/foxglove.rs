//! JSON-encoded Foxglove messages (`foxglove.RawImage`, `foxglove.CompressedImage`,
//! `foxglove.PoseInFrame`), as Foxglove's JSON convention and our own recorder
//! ([`crate::sim::record`]) write them: bytes as standard base64 strings, time as
//! `{"sec", "nsec"}`.
//!
//! Pure functions over `&[u8]`, so they can be fuzzed directly.

use crate::geometry::Pose2;
use crate::msgs::pixels::{PixelError, rgb_from_compressed, rgb_from_raw};
use crate::msgs::ros::yaw_of;
use crate::perception::RgbImage;
use serde::Deserialize;
use thiserror::Error;

/// Why a Foxglove JSON message did not decode.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum FoxgloveError {
    /// Not JSON, or a field missing or of the wrong type.
    #[error("not a {schema} JSON message: {why}")]
    Json {
        /// The schema expected.
        schema: &'static str,
        /// serde_json's message (names the field and column).
        why: String,
    },
    /// `data` is not standard base64.
    #[error("`data` is not standard base64: {why}")]
    Base64 {
        /// The decoder's message.
        why: String,
    },
}

/// `foxglove.Time`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
pub struct FoxgloveTime {
    /// Seconds.
    pub sec: u32,
    /// Nanoseconds.
    pub nsec: u32,
}

impl FoxgloveTime {
    /// Nanoseconds, or `None` for a zero stamp (fall back to the log time).
    pub fn ns(&self) -> Option<u64> {
        let ns = u64::from(self.sec) * 1_000_000_000 + u64::from(self.nsec);
        (ns > 0).then_some(ns)
    }
}

/// `foxglove.RawImage`, pixels decoded from base64.
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
pub struct RawImage {
    /// Capture time.
    #[serde(default)]
    pub timestamp: FoxgloveTime,
    /// The camera's frame.
    #[serde(default)]
    pub frame_id: String,
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Pixel encoding (as ROS's).
    pub encoding: String,
    /// Bytes per row.
    pub step: u32,
    /// Pixels (base64 in the JSON).
    #[serde(deserialize_with = "base64_field")]
    pub data: Vec<u8>,
}

impl RawImage {
    /// The frame as packed RGB8.
    ///
    /// # Errors
    /// [`PixelError`], as [`rgb_from_raw`].
    pub fn to_rgb(&self) -> Result<RgbImage, PixelError> {
        rgb_from_raw(self.width, self.height, &self.encoding, self.step, &self.data)
    }
}

/// `foxglove.CompressedImage`, bytes decoded from base64.
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
pub struct CompressedImage {
    /// Capture time.
    #[serde(default)]
    pub timestamp: FoxgloveTime,
    /// The camera's frame.
    #[serde(default)]
    pub frame_id: String,
    /// `jpeg`, `png` …
    pub format: String,
    /// The compressed bytes (base64 in the JSON).
    #[serde(deserialize_with = "base64_field")]
    pub data: Vec<u8>,
}

impl CompressedImage {
    /// The frame as packed RGB8.
    ///
    /// # Errors
    /// [`PixelError`], as [`rgb_from_compressed`].
    pub fn to_rgb(&self) -> Result<RgbImage, PixelError> {
        rgb_from_compressed(&self.format, &self.data)
    }
}

/// `foxglove.Vector3`-like position.
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize)]
struct Xyz {
    #[serde(default)]
    x: f64,
    #[serde(default)]
    y: f64,
    #[serde(default)]
    z: f64,
}

/// `foxglove.Quaternion`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
struct Quat {
    #[serde(default)]
    x: f64,
    #[serde(default)]
    y: f64,
    #[serde(default)]
    z: f64,
    #[serde(default = "one")]
    w: f64,
}

fn one() -> f64 {
    1.0
}

#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
struct Pose {
    #[serde(default)]
    position: Xyz,
    orientation: Quat,
}

/// `foxglove.PoseInFrame`: a pose in a named frame (our recorder's `/odometry`).
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct PoseInFrame {
    /// Time of the pose.
    #[serde(default)]
    pub timestamp: FoxgloveTime,
    /// The frame the pose is in.
    #[serde(default)]
    pub frame_id: String,
    #[serde(rename = "pose")]
    inner: Pose,
}

impl PoseInFrame {
    /// The planar pose (x, y, yaw).
    pub fn pose2(&self) -> Pose2 {
        let q = self.inner.orientation;
        Pose2::new(
            self.inner.position.x,
            self.inner.position.y,
            yaw_of([q.x, q.y, q.z, q.w]),
        )
    }
}

fn base64_field<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Vec<u8>, D::Error> {
    let s = <std::borrow::Cow<'de, str>>::deserialize(d)?;
    base64_simd::STANDARD
        .decode_to_vec(s.as_bytes())
        .map_err(|e| serde::de::Error::custom(format!("`data` is not standard base64: {e}")))
}

fn json<'a, T: Deserialize<'a>>(schema: &'static str, buf: &'a [u8]) -> Result<T, FoxgloveError> {
    serde_json::from_slice(buf).map_err(|e| {
        let why = e.to_string();
        if why.contains("base64") {
            FoxgloveError::Base64 { why }
        } else {
            FoxgloveError::Json { schema, why }
        }
    })
}

/// Decodes a JSON `foxglove.RawImage`.
///
/// # Errors
/// [`FoxgloveError`] naming what is wrong.
pub fn decode_raw_image(buf: &[u8]) -> Result<RawImage, FoxgloveError> {
    json("foxglove.RawImage", buf)
}

/// Decodes a JSON `foxglove.CompressedImage`.
///
/// # Errors
/// [`FoxgloveError`] naming what is wrong.
pub fn decode_compressed_image(buf: &[u8]) -> Result<CompressedImage, FoxgloveError> {
    json("foxglove.CompressedImage", buf)
}

/// Decodes a JSON `foxglove.PoseInFrame`.
///
/// # Errors
/// [`FoxgloveError`] naming what is wrong.
pub fn decode_pose_in_frame(buf: &[u8]) -> Result<PoseInFrame, FoxgloveError> {
    json("foxglove.PoseInFrame", buf)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn raw_image_with_leading_spaces_as_our_recorder_writes() {
        let m = br#"   {"timestamp":{"sec":1,"nsec":5},"frame_id":"cam0","width":1,"height":1,"encoding":"rgb8","step":3,"data":"AQID"}"#;
        let im = decode_raw_image(m).unwrap();
        assert_eq!(im.timestamp.ns(), Some(1_000_000_005));
        assert_eq!(im.to_rgb().unwrap().as_bytes(), &[1, 2, 3]);
    }

    #[test]
    fn errors_are_typed() {
        let bad = br#"{"width":1,"height":1,"encoding":"rgb8","step":3,"data":"!!"}"#;
        assert!(matches!(decode_raw_image(bad), Err(FoxgloveError::Base64 { .. })));
        assert!(matches!(decode_raw_image(b"{"), Err(FoxgloveError::Json { .. })));
        let p = decode_pose_in_frame(br#"{"pose":{"position":{"x":1,"y":2,"z":0},"orientation":{"x":0,"y":0,"z":0.7071067811865476,"w":0.7071067811865476}}}"#).unwrap();
        let q = p.pose2();
        assert!((q.x - 1.0).abs() < 1e-12 && (q.theta - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    }
}
