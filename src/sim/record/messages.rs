//! Foxglove's message types, as JSON (the subset of fields this recorder writes; see
//! [`super::schemas`]). Images are written by hand in [`super::McapRecorder`], base64
//! straight into a reused buffer.

use crate::geometry::Pose2;
use serde::Serialize;

/// A Foxglove timestamp: `{sec, nsec}`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Time {
    /// Whole seconds.
    pub sec: u32,
    /// Nanoseconds, 0–999,999,999.
    pub nsec: u32,
}

impl Time {
    /// From nanoseconds.
    pub fn from_ns(ns: u64) -> Self {
        Self {
            sec: (ns / 1_000_000_000) as u32,
            nsec: (ns % 1_000_000_000) as u32,
        }
    }
}

/// A point in image pixels.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Point2 {
    /// Column, px (0 at the left edge of the first pixel).
    pub x: f64,
    /// Row, px (0 at the top edge).
    pub y: f64,
}

/// An RGBA colour, channels in [0, 1].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Color {
    /// Red.
    pub r: f64,
    /// Green.
    pub g: f64,
    /// Blue.
    pub b: f64,
    /// Alpha.
    pub a: f64,
}

impl Color {
    /// An opaque colour from 8-bit channels.
    pub fn rgb8(rgb: [u8; 3]) -> Self {
        Self {
            r: rgb[0] as f64 / 255.0,
            g: rgb[1] as f64 / 255.0,
            b: rgb[2] as f64 / 255.0,
            a: 1.0,
        }
    }

    /// Fully transparent.
    pub const CLEAR: Color = Color {
        r: 0.0,
        g: 0.0,
        b: 0.0,
        a: 0.0,
    };
}

/// `foxglove.PointsAnnotation` (`type`: 1 points, 2 line loop, 3 line strip).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PointsAnnotation {
    /// Time of the image it annotates.
    pub timestamp: Time,
    /// How the points are drawn.
    #[serde(rename = "type")]
    pub kind: u8,
    /// The points.
    pub points: Vec<Point2>,
    /// Outline colour.
    pub outline_color: Color,
    /// Per-point colours (unused: empty).
    pub outline_colors: Vec<Color>,
    /// Fill colour.
    pub fill_color: Color,
    /// Line width, px.
    pub thickness: f64,
}

/// `foxglove.CircleAnnotation`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CircleAnnotation {
    /// Time of the image it annotates.
    pub timestamp: Time,
    /// Centre, px.
    pub position: Point2,
    /// Diameter, px.
    pub diameter: f64,
    /// Outline width, px.
    pub thickness: f64,
    /// Fill colour.
    pub fill_color: Color,
    /// Outline colour.
    pub outline_color: Color,
}

/// `foxglove.TextAnnotation`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TextAnnotation {
    /// Time of the image it annotates.
    pub timestamp: Time,
    /// Bottom-left of the text, px.
    pub position: Point2,
    /// The text.
    pub text: String,
    /// Font size, px.
    pub font_size: f64,
    /// Text colour.
    pub text_color: Color,
    /// Background colour.
    pub background_color: Color,
}

/// `foxglove.ImageAnnotations`.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct ImageAnnotations {
    /// Circles.
    pub circles: Vec<CircleAnnotation>,
    /// Point sets: outlines, boxes, centroids.
    pub points: Vec<PointsAnnotation>,
    /// Texts.
    pub texts: Vec<TextAnnotation>,
}

/// `foxglove.Vector3`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Vector3 {
    /// x, m.
    pub x: f64,
    /// y, m.
    pub y: f64,
    /// z, m.
    pub z: f64,
}

/// `foxglove.Quaternion`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Quaternion {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
    /// w.
    pub w: f64,
}

impl Quaternion {
    /// A rotation by `yaw` radians about +z.
    pub fn yaw(yaw: f64) -> Self {
        let (s, c) = (yaw / 2.0).sin_cos();
        Self {
            x: 0.0,
            y: 0.0,
            z: s,
            w: c,
        }
    }

    /// The Hamilton product `self · o` (rotate by `o`, then by `self`).
    pub fn mul(&self, o: &Quaternion) -> Quaternion {
        let (a, b) = (self, o);
        Quaternion {
            w: a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
            x: a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
            y: a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
            z: a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w,
        }
    }

    /// Rotation from roll (about +x), pitch (about +y) and yaw (about +z), applied in
    /// that order (z·y·x).
    pub fn from_euler(roll: f64, pitch: f64, yaw: f64) -> Self {
        let (sr, cr) = (roll / 2.0).sin_cos();
        let (sp, cp) = (pitch / 2.0).sin_cos();
        let (sy, cy) = (yaw / 2.0).sin_cos();
        Quaternion {
            w: cr * cp * cy + sr * sp * sy,
            x: sr * cp * cy - cr * sp * sy,
            y: cr * sp * cy + sr * cp * sy,
            z: cr * cp * sy - sr * sp * cy,
        }
    }
}

/// `foxglove.Pose`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Pose {
    /// Position, m.
    pub position: Vector3,
    /// Orientation.
    pub orientation: Quaternion,
}

impl From<&Pose2> for Pose {
    fn from(p: &Pose2) -> Self {
        Pose {
            position: Vector3 { x: p.x, y: p.y, z: 0.0 },
            orientation: Quaternion::yaw(p.theta),
        }
    }
}

/// `foxglove.PoseInFrame`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PoseInFrame<'a> {
    /// Time.
    pub timestamp: Time,
    /// The frame the pose is in.
    pub frame_id: &'a str,
    /// The pose.
    pub pose: Pose,
}

/// `foxglove.FrameTransform`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrameTransform<'a> {
    /// Time.
    pub timestamp: Time,
    /// Parent frame.
    pub parent_frame_id: &'a str,
    /// Child frame.
    pub child_frame_id: &'a str,
    /// The child's origin in the parent, m.
    pub translation: Vector3,
    /// The child's orientation in the parent.
    pub rotation: Quaternion,
}

impl<'a> FrameTransform<'a> {
    /// The planar pose `p` of `child` in `parent`.
    pub fn planar(timestamp: Time, parent: &'a str, child: &'a str, p: &Pose2) -> Self {
        let pose = Pose::from(p);
        Self {
            timestamp,
            parent_frame_id: parent,
            child_frame_id: child,
            translation: pose.position,
            rotation: pose.orientation,
        }
    }
}

/// `foxglove.Log`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Log<'a> {
    /// Time.
    pub timestamp: Time,
    /// 1 debug, 2 info, 3 warning, 4 error, 5 fatal.
    pub level: u8,
    /// The line.
    pub message: &'a str,
    /// The logger's name.
    pub name: &'a str,
    /// Source file (empty).
    pub file: &'a str,
    /// Source line (0).
    pub line: u32,
}

/// `foxglove.CameraCalibration` (pin-hole, `plumb_bob`).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[allow(non_snake_case)]
pub struct CameraCalibration<'a> {
    /// Time.
    pub timestamp: Time,
    /// The camera's frame.
    pub frame_id: &'a str,
    /// Image width, px.
    pub width: u32,
    /// Image height, px.
    pub height: u32,
    /// `plumb_bob`.
    pub distortion_model: &'a str,
    /// k1, k2, p1, p2, k3.
    pub D: [f64; 5],
    /// Intrinsic matrix, row-major.
    pub K: [f64; 9],
    /// Rectification (identity).
    pub R: [f64; 9],
    /// Projection matrix, row-major 3×4.
    pub P: [f64; 12],
}
