//! Perception: pure image functions that write into caller-owned buffers.
//!
//! Everything here is a plain function or a struct that allocates its scratch space once
//! and reuses it every frame; nothing reads a clock or a random source.
//!
//! Perception is a bottom layer: it knows nothing of profiles, schemas or the simulator
//! (CI checks that nothing here names them). Every detector and tracker is built from a
//! plain parameter struct ([`TwoBlockParams`], [`PyramidParams`],
//! [`PyramidTrackerParams`], [`ColorModelParams`], [`MountAngles`] …). The adapters sit
//! above: `profile` turns a profile's tables into these structs
//! (`TwoBlockParams::from_profile`, `CameraModel::from_spec` …), and `schemas` runs the
//! trackers as perceptual schemas over a tick's inputs (`schemas::TwoBlockSchema`,
//! `schemas::PyramidSchema`).
//!
//! * [`camera_model`]: pin-hole and omnidirectional projection, camera mounting.
//! * [`sct`] and [`hsv`]: colour spaces, exact per pixel and fast over whole frames.
//! * [`cast`]: removing fast colour casts (a flashing coloured light) before segmentation.
//! * [`segment`]: per-colour ranges into reusable [`Mask`]s (the SCT test is trig-free).
//! * [`spurs`]: the pixels that stick out of a block's edge (noise touching it), kept out of its count.
//! * [`components`]: 8-connected labelling with per-component moments.
//! * [`colour_model`]: imprinting, adaptation and the fallback chain of seed 004 Fig. 5.
//! * [`hsv_stats`]: the HSV statistics that chain uses for RAPOSA's bands.
//! * [`two_block`] and [`two_block_pose`]: Bujold's two-block fiducial detector, its
//!   tracker (colour model and imprinting) and the relative pose it gives.
//! * [`pyramid`], [`pyramid_pose`] and [`pyramid_tracker`]: RAPOSA's pyramid detector, its
//!   geometry, and its tracker with fixed, imprinted or adapted HSV bands.
//! * [`circles`]: Axel's circle fiducials: detection, correspondence to the module's
//!   model by homography, and pose.
//! * [`apriltag`]: AprilTag fiducials (tag36h11 and kin): detection, id, pose and its
//!   covariance, and the check that rejects a wrong id, a small tag or an uncertain pose.
//! * [`overlay`]: drawing a detection over its frame.

pub mod apriltag;
pub mod camera_model;
pub mod cast;
pub mod circles;
pub mod colour_model;
pub mod components;
pub mod fastmath;
pub mod flow;
pub mod frame_change;
pub mod hsv;
pub mod hsv_stats;
pub mod image;
pub mod krawler;
pub mod overlay;
pub mod pyramid;
pub mod pyramid_pose;
pub mod pyramid_tracker;
pub mod sct;
pub mod segment;
pub mod spurs;
pub mod two_block;
pub mod two_block_pose;

pub use camera_model::{CameraModel, Fisheye, MountAngles, Pinhole, body_from_camera};
pub use cast::{CastCompensator, CastParams};
pub use colour_model::{
    AngleStats, Blend, ColorMode, ColorModel, ColorModelParams, Imprinter, SegmentationMode, StatsAccumulator,
};
pub use components::{Component, Labeler, Run};
pub use hsv::{Hsv, HsvPlanes, hsv_from_rgb};
pub use hsv_stats::{HsvAccumulator, HsvLimits, HsvStats};
pub use image::{ImageError, RgbImage, RgbView, srgb_to_linear};
pub use krawler::{
    AxleGeometry, GearGeometry, GearSpec, KrawlerEstimate, KrawlerParams, KrawlerStateSchema, SteeringPoly, WheelStep,
};
pub use pyramid::{BlueRegion, Ellipse, PyramidDetection, PyramidDetector, PyramidPair, PyramidParams, PyramidShape};
pub use pyramid_pose::{PyramidGeometry, PyramidPercept, PyramidView};
pub use pyramid_tracker::{PyramidTracker, PyramidTrackerParams};
pub use sct::{Sct, SctPlanes, sct_from_rgb};
pub use segment::{ColorRange, HsvRange, Mask, SctRange, Segmenter};
pub use two_block::{Block, Pair, PairLimits, TwoBlockDetector, TwoBlockParams, TwoBlockPercept, TwoBlockTracker};
pub use two_block_pose::{FiducialView, RatioJumpGate, TwoBlockGeometry};

use thiserror::Error;

/// Errors of the vision functions: inconsistent sizes, never pixel content.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum VisionError {
    /// An output or scratch buffer does not match the input's size.
    #[error("size mismatch: expected {expected:?}, got {got:?}")]
    SizeMismatch {
        /// Expected (width, height).
        expected: (usize, usize),
        /// Found (width, height).
        got: (usize, usize),
    },
    /// Two lists that must pair up differ in length.
    #[error("{what}: expected {expected}, got {got}")]
    CountMismatch {
        /// What was counted.
        what: &'static str,
        /// Expected count.
        expected: usize,
        /// Found count.
        got: usize,
    },
    /// The frame has no pixels.
    #[error("empty image")]
    EmptyImage,
    /// The configuration lacks what a detector needs (e.g. a profile without the
    /// fiducial or the camera a schema is built for).
    #[error("{what}")]
    Profile {
        /// What is missing.
        what: String,
    },
}

pub(crate) fn check_same_size(expected: (usize, usize), got: (usize, usize)) -> Result<(), VisionError> {
    if expected == got {
        Ok(())
    } else {
        Err(VisionError::SizeMismatch { expected, got })
    }
}
