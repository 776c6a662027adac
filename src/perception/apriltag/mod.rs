//! AprilTag fiducials (tag36h11, tag25h9, tag16h5): detection, decoding and pose with its
//! covariance, for a dock marked by one tag of known id and size.
//!
//! Our own implementation of the AprilTag 3 pipeline (Wang & Olson, IROS 2016), simplified
//! where a docking camera allows it. Per frame, [`AprilTagDetector::detect`]:
//!
//! * binarises with a tiled min/max threshold ([`threshold`]);
//! * labels the black regions ([`crate::perception::Labeler`]) and traces the outer
//!   contour of each that could hold a tag, keeps those that are convex quads with
//!   straight sides, and refines their corners to the grey image's edges ([`quad`]);
//! * reads the cells through the quad's homography, with the tag's own border as the
//!   threshold and checks on contrast, border and margin ([`cells`]);
//! * decodes the bits against the family's codes in four rotations, correcting up to
//!   [`AprilTagParams::max_hamming`] bits ([`family`], code tables in [`codes`]);
//! * fits the tag's pose from its corners, the camera's intrinsics and the tag's size,
//!   with a first-order covariance from the reprojection Jacobian ([`pose`]).
//!
//! [`AprilTagParams::accept`] is the check a schema makes before trusting a detection:
//! the dock's id, a tag large enough in the image, a finite pose, a covariance within
//! bounds, each refusal a typed [`TagRejection`]. [`render::draw_tag`] draws a tag
//! through a pin-hole camera with antialiasing, for tests and benches.
//!
//! Simplified against AprilTag 3: no decimation, no blur or sharpening, quads from black
//! components' contours rather than from clustered edge pixels (a tag whose black border
//! touches other black, diagonally included, is not found), one global black/white level
//! per tag rather than a fitted gradient, families with a normal (black) border only.
//! Why not a crate: `kornia-apriltag` 0.2 (Apache-2.0) is maintained and fast, but brings
//! about 170 crates (faer, gemm, rayon, rand, bincode …) and runs its stages on rayon's
//! threads, against a core that builds with few dependencies and runs deterministically
//! on one thread.

pub mod cells;
pub mod codes;
pub mod detect;
pub mod family;
pub mod params;
pub mod pose;
pub mod quad;
pub mod render;
pub mod threshold;

pub use detect::AprilTagDetector;
pub use family::{Decoded, MAX_CELLS, TagFamily};
pub use params::{AprilTagParams, TagDetection, TagRejection};
pub use pose::{TagPose, project_corners, tag_corners, tag_pose};
pub use render::{INK, PAPER, TagSprite, draw_tag};
pub use threshold::{TileThreshold, TileThresholder, grey_into};

#[cfg(test)]
mod tests;
