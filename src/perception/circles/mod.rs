//! Axel's circle fiducials (seed 000 §III): detection, correspondence to the module's
//! model, and pose.
//!
//! Eight 10 cm circle marks, each with one of four bar rotations, sit on the central
//! module's face in an asymmetric layout. Per camera frame:
//!
//! * [`CircleDetector`] finds the marks: an adaptive threshold, black and white blobs
//!   filtered by size, eccentricity and Euler number ([`RunIndex`]), black/white pairs
//!   with coinciding centroids, a local re-threshold for the bar's rotation, and the
//!   centre from a direct least-squares ellipse fit ([`fit_ellipse`]) of the perimeter;
//! * [`correspond()`] labels them against a [`CircleModel`]: the rotations split the 8!
//!   labellings into at most 16 hypotheses, each verified by a homography
//!   ([`Homography`], normalised DLT) and its reprojection; far points are occlusions or
//!   false positives, and no fit from fewer than 5 marks is ever accepted;
//!   [`correspond_through`] does it through a distorting lens, on the detections moved
//!   onto the lens's ideal pin-hole image ([`LensPlane`]), where the face's marks obey a
//!   homography;
//! * [`module_pose`] turns the labelled marks ([`MarkObservations`]) into the module's
//!   pose in the rover frame ([`ModulePose`]): midpoint triangulation of the marks both
//!   cameras detected and a least-squares rigid (SVD) fit ([`stereo_pose`]), or, when
//!   only one camera sees the module, the planar pose from a homography on undistorted
//!   normalised coordinates ([`mono_pose`]).
//!
//! Everything is a pure function over borrowed data or a struct that allocates its
//! buffers once; nothing allocates per frame.

pub mod blobs;
pub mod correspond;
pub mod detect;
pub mod ellipse;
pub mod homography;
pub mod model;
pub mod pose;
pub mod rectify;
pub mod threshold;

pub use blobs::RunIndex;
pub use correspond::{CorrespondenceError, CorrespondenceParams, MAX_DETECTIONS, ModelFit, correspond};
pub use detect::{CircleDetector, CircleParams, DetectedMark, MarkRotation};
pub use ellipse::{Ellipse, EllipseFit, fit_ellipse};
pub use homography::Homography;
pub use model::{CircleModel, MAX_MODEL_MARKS, ModelError};
pub use pose::{
    MarkObservations, ModulePose, PoseBuffers, PoseError, PoseParams, PoseSource, RigCamera, module_pose, mono_pose,
    rigid_fit, stereo_pose,
};
pub use rectify::{LensPlane, correspond_through};
pub use threshold::{AdaptiveThreshold, FixedThreshold, Threshold, Thresholder, grey_from_rgb};
