//! The detector: one reusable state that turns a frame into decoded, posed tags.
//!
//! Per frame: grey ([`grey_into`]), the tiled threshold's black mask
//! ([`TileThresholder`]), 8-connected black components ([`Labeler`]), and for each
//! component whose bounding box could hold a tag, its contour, quad, refined corners,
//! cells, code and pose (see the sibling modules). All buffers live in the detector and
//! keep their capacity between frames, so steady-state detection does not allocate.

use super::cells::{CellLimits, SquareMap, read_cells};
use super::params::{AprilTagParams, TagDetection};
use super::pose::tag_pose;
use super::quad::{quad_corners, refine_corners, trace_contour};
use super::threshold::{TileThresholder, grey_into};
use crate::perception::camera_model::Pinhole;
use crate::perception::image::RgbView;
use crate::perception::{Labeler, Mask, VisionError};

/// An AprilTag detector with its scratch buffers.
///
/// # Example
///
/// A tag rendered 1 m in front of a 640 × 480 camera is found with its id and pose.
///
/// ```
/// use marsupial::perception::{Pinhole, RgbImage};
/// use marsupial::perception::apriltag::{AprilTagDetector, AprilTagParams, TagFamily, TagSprite, draw_tag};
/// use nalgebra::{Matrix3, Vector3};
///
/// let cam = Pinhole::ideal(600.0, 640, 480);
/// let mut frame = RgbImage::new(640, 480);
/// frame.fill([128, 128, 128]);
/// let facing = Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, -1.0));
/// let tag = TagSprite { family: TagFamily::Tag36h11, id: 42, size_m: 0.16, supersample: 3 };
/// draw_tag(&mut frame, &cam, &tag, &facing, &Vector3::new(0.05, 0.0, 1.0));
///
/// let params = AprilTagParams { expected_id: Some(42), ..AprilTagParams::default() };
/// let mut det = AprilTagDetector::new(params);
/// let found = det.detect(&frame.view(), &cam).unwrap();
/// assert_eq!(found.len(), 1);
/// let pose = params.accept(&found[0]).unwrap();
/// assert!((pose.translation - Vector3::new(0.05, 0.0, 1.0)).norm() < 0.01);
/// ```
#[derive(Debug, Clone)]
pub struct AprilTagDetector {
    params: AprilTagParams,
    grey: Vec<u8>,
    thresholder: TileThresholder,
    black: Mask,
    labeler: Labeler,
    first_run: Vec<u32>,
    contour: Vec<[f64; 2]>,
    found: Vec<TagDetection>,
}

impl AprilTagDetector {
    /// A detector for `params`; its buffers grow to the first frame's size and stay.
    pub fn new(params: AprilTagParams) -> Self {
        Self {
            params,
            grey: Vec::new(),
            thresholder: TileThresholder::default(),
            black: Mask::default(),
            labeler: Labeler::new(0, 0),
            first_run: Vec::new(),
            contour: Vec::new(),
            found: Vec::with_capacity(16),
        }
    }

    /// The parameters.
    pub fn params(&self) -> &AprilTagParams {
        &self.params
    }

    /// The black mask of the last frame (1 = black): for overlays and debugging.
    pub fn black_mask(&self) -> &Mask {
        &self.black
    }

    /// Detects the tags of an RGB frame seen through `camera`.
    ///
    /// # Errors
    /// [`VisionError::EmptyImage`] for a frame with no pixels.
    pub fn detect(&mut self, frame: &RgbView<'_>, camera: &Pinhole) -> Result<&[TagDetection], VisionError> {
        if frame.is_empty() {
            self.found.clear();
            return Err(VisionError::EmptyImage);
        }
        let mut grey = std::mem::take(&mut self.grey);
        grey_into(frame, &mut grey);
        self.detect_in(&grey, frame.width(), frame.height(), camera);
        self.grey = grey;
        Ok(&self.found)
    }

    /// Detects the tags of a grey frame (row-major, `width × height` bytes).
    ///
    /// # Errors
    /// [`VisionError::EmptyImage`] for no pixels, [`VisionError::SizeMismatch`] when
    /// `grey` is not `width × height` bytes.
    pub fn detect_grey(
        &mut self,
        grey: &[u8],
        width: usize,
        height: usize,
        camera: &Pinhole,
    ) -> Result<&[TagDetection], VisionError> {
        self.found.clear();
        if width == 0 || height == 0 {
            return Err(VisionError::EmptyImage);
        }
        if grey.len() != width * height {
            return Err(VisionError::SizeMismatch {
                expected: (width, height),
                got: (grey.len(), 1),
            });
        }
        self.detect_in(grey, width, height, camera);
        Ok(&self.found)
    }

    fn detect_in(&mut self, grey: &[u8], w: usize, h: usize, camera: &Pinhole) {
        self.found.clear();
        let p = self.params;
        self.thresholder.apply(grey, w, h, &p.threshold, &mut self.black);
        if self.labeler.size() != (w, h) {
            self.labeler = Labeler::new(w, h);
        }
        let Ok(count) = self.labeler.label(&self.black).map(|c| c.len()) else {
            return;
        };
        // Each component's first run (runs are in raster order): its contour's start.
        self.first_run.clear();
        self.first_run.resize(count, u32::MAX);
        for (i, r) in self.labeler.runs().iter().enumerate() {
            if let Some(f) = self.first_run.get_mut(r.label as usize)
                && *f == u32::MAX
            {
                *f = i as u32;
            }
        }
        let min_side = p.min_side_px.max(4.0);
        let limits = CellLimits {
            min_contrast: p.min_tag_contrast,
            max_border_errors: p.max_border_errors,
            min_margin: p.min_margin,
        };
        let mut traced = 0usize;
        for (label, c) in self.labeler.components().iter().enumerate() {
            let (bw, bh) = (c.width() as f64, c.height() as f64);
            // A quad with sides ≥ min_side spans at least that much one way and 0.7 of it
            // the other (a square at 45°); its border covers a tenth of its box or more.
            if bw.max(bh) < min_side || bw.min(bh) < 0.7 * min_side || (c.count as f64) < 0.1 * bw * bh {
                continue;
            }
            // Touching the frame's edge: the white ring is cut off.
            if c.bbox[0] == 0 || c.bbox[1] == 0 || c.bbox[2] as usize + 1 >= w || c.bbox[3] as usize + 1 >= h {
                continue;
            }
            if traced >= p.max_candidates {
                break;
            }
            traced += 1;
            let Some(run) = self
                .first_run
                .get(label)
                .and_then(|&i| self.labeler.runs().get(i as usize))
            else {
                continue;
            };
            let max_len = 4 * (c.width() + c.height()) as usize + 16;
            if !trace_contour(self.black.data(), w, h, (run.x0, run.y), max_len, &mut self.contour) {
                continue;
            }
            let Some(rough) = quad_corners(&self.contour, min_side) else {
                continue;
            };
            let Some(corners) = refine_corners(grey, w, h, rough) else {
                continue;
            };
            let Some(map) = SquareMap::new(&corners) else { continue };
            let Some(cells) = read_cells(grey, w, h, &map, p.family, &limits) else {
                continue;
            };
            let Some(code) = p.family.decode(&cells.grid, p.max_hamming) else {
                continue;
            };
            // The tag's corner j is the quad's corner j + rotation.
            let k = code.rotation as usize;
            let tag_corners = [0, 1, 2, 3].map(|j| corners[(j + k) % 4]);
            let side = (0..4)
                .map(|j| {
                    let (a, b) = (tag_corners[j], tag_corners[(j + 1) % 4]);
                    (a[0] - b[0]).hypot(a[1] - b[1])
                })
                .fold(f64::INFINITY, f64::min);
            let det = TagDetection {
                family: p.family,
                id: code.id,
                hamming: code.hamming,
                corners: tag_corners,
                center: map.apply(0.5, 0.5),
                min_side_px: side,
                contrast: cells.contrast,
                margin: cells.margin,
                pose: tag_pose(&tag_corners, camera, p.tag_size_m, p.corner_sigma_px),
            };
            self.found.push(det);
        }
    }
}
