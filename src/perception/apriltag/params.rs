//! The detector's parameters, its detections, and the check a schema makes before it
//! trusts one.

use super::family::TagFamily;
use super::pose::TagPose;
use super::threshold::TileThreshold;
use serde::Serialize;
use thiserror::Error;

/// What the detector looks for and when a detection is trusted (plain data; a profile's
/// fiducial table becomes one above this layer).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AprilTagParams {
    /// The tag family.
    pub family: TagFamily,
    /// Side of the tag's black border, m (what the pose is scaled by).
    pub tag_size_m: f64,
    /// The dock's tag id; `None` accepts any id of the family.
    pub expected_id: Option<u32>,
    /// Quads whose shortest side is shorter than this are not decoded, px (default 10:
    /// 1.25 px per cell for tag36h11, about the least that decodes).
    pub min_side_px: f64,
    /// Bits a decode may correct (clamped to the family's
    /// [`TagFamily::max_correctable`]): more finds more tags and more false ones. Default
    /// 2 for tag36h11; [`AprilTagParams::for_family`] gives 0 for tag25h9 and tag16h5,
    /// whose codes are close enough that an ArUco marker in a real photo decoded as a
    /// tag25h9 at 2 bits.
    pub max_hamming: u32,
    /// The binarisation that finds black borders.
    pub threshold: TileThreshold,
    /// Least grey difference between a tag's white ring and black border (default 30).
    pub min_tag_contrast: f64,
    /// Border and ring cells allowed on the wrong side of the tag's midpoint (default 2
    /// of the 60 for tag36h11: a specular spot or a smudge).
    pub max_border_errors: u32,
    /// Least mean margin of the data cells from the midpoint, half-contrasts (default
    /// 0.35).
    pub min_margin: f64,
    /// The corners' standard deviation per coordinate, px, which scales the pose's
    /// covariance (default 0.5).
    pub corner_sigma_px: f64,
    /// [`AprilTagParams::accept`] refuses a tag seen with a shortest side below this, px
    /// (default 16: two pixels per cell of tag36h11).
    pub min_trusted_side_px: f64,
    /// [`AprilTagParams::accept`] refuses a pose whose position is more uncertain than
    /// this, m (largest standard deviation over directions; default 0.05).
    pub max_position_sigma_m: f64,
    /// [`AprilTagParams::accept`] refuses a pose whose rotation is more uncertain than
    /// this, rad (largest standard deviation over axes; default 0.1, about 6°).
    pub max_angle_sigma_rad: f64,
    /// Black components traced per frame at most, largest first not guaranteed (default
    /// 512): bounds the time on a frame of noise.
    pub max_candidates: usize,
}

impl Default for AprilTagParams {
    fn default() -> Self {
        Self {
            family: TagFamily::Tag36h11,
            tag_size_m: 0.16,
            expected_id: None,
            min_side_px: 10.0,
            max_hamming: 2,
            threshold: TileThreshold::default(),
            min_tag_contrast: 30.0,
            max_border_errors: 2,
            min_margin: 0.35,
            corner_sigma_px: 0.5,
            min_trusted_side_px: 16.0,
            max_position_sigma_m: 0.05,
            max_angle_sigma_rad: 0.1,
            max_candidates: 512,
        }
    }
}

/// One decoded tag. Pixel coordinates have their origin at the top-left pixel's centre,
/// x right, y down.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TagDetection {
    /// The family decoded.
    pub family: TagFamily,
    /// The tag's id in its family.
    pub id: u32,
    /// Bits corrected.
    pub hamming: u32,
    /// The black border's outer corners, px, as the tag is printed: top-left, top-right,
    /// bottom-right, bottom-left (clockwise in the image when the tag is upright).
    pub corners: [[f64; 2]; 4],
    /// The tag's centre (where its diagonals cross), px.
    pub center: [f64; 2],
    /// Shortest side of the quad, px.
    pub min_side_px: f64,
    /// Grey difference between the white ring and the black border.
    pub contrast: f64,
    /// Mean margin of the data cells, half-contrasts (1 is a perfect print).
    pub margin: f64,
    /// The pose from the corners, `None` when no pose could be fitted.
    pub pose: Option<TagPose>,
}

/// Why [`AprilTagParams::accept`] refused a detection.
#[derive(Debug, Clone, Copy, PartialEq, Error, Serialize)]
pub enum TagRejection {
    /// The tag is not the dock's.
    #[error("tag {found} is not the dock's tag {expected}")]
    WrongId {
        /// The id decoded.
        found: u32,
        /// The dock's id.
        expected: u32,
    },
    /// The tag is seen too small for its corners to be trusted.
    #[error("tag seen {side_px:.1} px across, the least trusted is {min_px} px")]
    TooSmall {
        /// Shortest side, px.
        side_px: f64,
        /// [`AprilTagParams::min_trusted_side_px`].
        min_px: f64,
    },
    /// No pose was fitted.
    #[error("no pose")]
    NoPose,
    /// The pose or its covariance has a NaN or an infinity.
    #[error("the pose has a non-finite number")]
    NotFinite,
    /// The covariance is larger than the limits.
    #[error("pose too uncertain: σ position {position_sigma_m:.3} m, σ angle {angle_sigma_rad:.3} rad")]
    Uncertain {
        /// Largest position standard deviation, m.
        position_sigma_m: f64,
        /// Largest angle standard deviation, rad.
        angle_sigma_rad: f64,
    },
}

impl AprilTagParams {
    /// The defaults for `family`: those of [`Default`] with the family's own
    /// [`AprilTagParams::max_hamming`] (2 for tag36h11, 0 for the smaller families).
    pub fn for_family(family: TagFamily) -> Self {
        let max_hamming = match family {
            TagFamily::Tag36h11 => 2,
            TagFamily::Tag25h9 | TagFamily::Tag16h5 => 0,
        };
        Self {
            family,
            max_hamming,
            ..Self::default()
        }
    }

    /// Checks a detection as a schema must before it uses it: the dock's id, large
    /// enough, a finite pose, a covariance within the limits (in that order; the first
    /// failure is returned).
    ///
    /// # Errors
    /// The [`TagRejection`] that applies.
    pub fn accept(&self, d: &TagDetection) -> Result<TagPose, TagRejection> {
        if let Some(expected) = self.expected_id
            && d.id != expected
        {
            return Err(TagRejection::WrongId { found: d.id, expected });
        }
        if d.min_side_px.is_nan() || d.min_side_px < self.min_trusted_side_px {
            return Err(TagRejection::TooSmall {
                side_px: d.min_side_px,
                min_px: self.min_trusted_side_px,
            });
        }
        let pose = d.pose.ok_or(TagRejection::NoPose)?;
        if !pose.is_finite() {
            return Err(TagRejection::NotFinite);
        }
        let (ps, as_) = (pose.position_sigma_m(), pose.angle_sigma_rad());
        if !(ps <= self.max_position_sigma_m && as_ <= self.max_angle_sigma_rad) {
            return Err(TagRejection::Uncertain {
                position_sigma_m: ps,
                angle_sigma_rad: as_,
            });
        }
        Ok(pose)
    }
}
