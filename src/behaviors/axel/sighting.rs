//! What one look of Axel's perception yields ([`Sighting`]: the rover's pose in the
//! module frame with the pose's quality figures) and when a schema may plan on it
//! ([`Trust`]).

use crate::geometry::Pose2;
use crate::perception::circles::PoseSource;
use serde::Deserialize;

/// One pose measurement: where the rover is in the module frame, and how good it is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sighting {
    /// Loop time of the frames, s.
    pub t: f64,
    /// The rover's pose in the module frame (mouth at the origin, face looking +x).
    pub pose: Pose2,
    /// Stereo or mono.
    pub source: PoseSource,
    /// Marks the pose came from.
    pub marks: usize,
    /// RMS reprojection of the posed model against the detections, px.
    pub reprojection_px: f64,
    /// RMS metric residual of the fit, m.
    pub residual_m: f64,
}

/// The quality a sighting must have to be planned on (node params `trust`, ours: the
/// paper accepted any pose its correspondence produced, and its monocular poses, with no
/// distortion model, misled it, §V-E).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Trust {
    /// Largest RMS reprojection error, px.
    pub reprojection_px: f64,
    /// Largest RMS metric residual, m.
    pub residual_m: f64,
    /// Fewest marks.
    pub marks: usize,
    /// Accept a monocular pose (one camera saw the module).
    pub mono: bool,
}

impl Default for Trust {
    fn default() -> Self {
        Self {
            reprojection_px: 3.0,
            residual_m: 0.05,
            marks: 5,
            mono: true,
        }
    }
}

impl Trust {
    /// True when `s` is good enough to plan on.
    pub fn accepts(&self, s: &Sighting) -> bool {
        s.marks >= self.marks
            && s.reprojection_px <= self.reprojection_px
            && s.residual_m <= self.residual_m
            && (self.mono || s.source == PoseSource::Stereo)
            && s.pose.is_finite()
    }
}
