//! Bujold's close-dock perceptual schema: the two-block tracker of perception run on one
//! camera of a tick's [`Inputs`].

use super::{Inputs, Percept, PerceptualSchema};
use crate::perception::{TwoBlockParams, TwoBlockPercept, TwoBlockTracker, VisionError};
use crate::profile::Profile;
use std::ops::{Deref, DerefMut};

impl Percept for TwoBlockPercept {
    fn stamp(&self) -> f64 {
        self.stamp
    }
    fn found(&self) -> bool {
        self.found
    }
}

/// The close-dock perceptual schema: a [`TwoBlockTracker`] bound to one camera. It
/// dereferences to the tracker, so the tracker's methods (`process`, `model`,
/// `imprint_frame`, `finish_imprint` …) are called on the schema directly.
///
/// # Example
///
/// A 16×8 frame on camera 0 with 4×4 cyan and magenta blocks side by side (x = 4…11),
/// tracked with the table colours: the percept is found, stamped with the frame's time,
/// and its pair sits half a pixel left of the image centre. A tick without a frame
/// gives "not found" at the tick's time.
///
/// ```
/// use marsupial::perception::{CastParams, ColorModelParams, PairLimits, RgbImage, SegmentationMode, TwoBlockParams};
/// use marsupial::schemas::{CameraInput, Inputs, Percept, PerceptualSchema, TwoBlockSchema};
///
/// let (cyan, magenta) = ([20, 190, 210], [200, 30, 190]);
/// let mut im = RgbImage::new(16, 8);
/// im.fill([110, 105, 100]);
/// for y in 2..6 {
///     (4..8).for_each(|x| im.put(x, y, cyan));
///     (8..12).for_each(|x| im.put(x, y, magenta));
/// }
/// let params = TwoBlockParams {
///     width: 16,
///     height: 8,
///     colours: [cyan, magenta],
///     table_sd: 0.05,
///     limits: PairLimits {
///         min_component_px: 8,
///         max_gap_frac: 0.5,
///         gap_slack_px: 3.0,
///         max_vertical_frac: 0.5,
///         max_height_ratio: 2.0,
///         min_count_ratio: 0.2,
///         max_candidates: 8,
///     },
///     colour: ColorModelParams {
///         n_sd: 4.0,
///         sd_floor: 0.01,
///         sd_ceiling: 0.2,
///         min_l: 20.0,
///         min_chroma: 0.05,
///         timeout1: 2.0,
///         timeout2: 5.0,
///         adaptive: false,
///         adapt_rate: 1.0,
///     },
///     mode: SegmentationMode::Fixed,
///     imprint_rects: [[0.25, 0.25, 0.5, 0.75], [0.5, 0.25, 0.75, 0.75]],
///     imprint_sample_frac: 0.5,
///     imprint_frames: 1,
///     cast: CastParams::OFF,
/// };
/// let mut schema = TwoBlockSchema::new(0, &params);
/// let cameras = [Some(CameraInput { stamp: 0.1, image: im.view() })];
/// let p = schema.perceive(&Inputs { cameras: &cameras, ..Inputs::empty(0.12) });
/// assert!(p.found() && p.confidence() == 1.0);
/// assert_eq!(p.stamp(), 0.1);
/// assert_eq!((p.left_px, p.right_px), (16, 16));
/// assert_eq!(p.offset_px, -0.5);
///
/// let p = schema.perceive(&Inputs::empty(0.2));
/// assert!(!p.found() && p.stamp() == 0.2);
/// ```
#[derive(Debug, Clone)]
pub struct TwoBlockSchema {
    camera: usize,
    tracker: TwoBlockTracker,
}

impl TwoBlockSchema {
    /// The tracker built from `params`, reading camera `camera` of the inputs.
    pub fn new(camera: usize, params: &TwoBlockParams) -> Self {
        Self {
            camera,
            tracker: TwoBlockTracker::new(params),
        }
    }

    /// Builds the schema for camera `camera` of `profile`, which needs a
    /// `two_block` fiducial (see [`TwoBlockParams::from_profile`]).
    ///
    /// # Errors
    /// [`VisionError::Profile`] when the profile has no two-block fiducial or no such camera.
    pub fn from_profile(profile: &Profile, camera: usize) -> Result<Self, VisionError> {
        Ok(Self::new(camera, &TwoBlockParams::from_profile(profile, camera)?))
    }

    /// The camera index the schema reads.
    pub fn camera(&self) -> usize {
        self.camera
    }

    /// The tracker.
    pub fn tracker(&self) -> &TwoBlockTracker {
        &self.tracker
    }

    /// The tracker, mutable.
    pub fn tracker_mut(&mut self) -> &mut TwoBlockTracker {
        &mut self.tracker
    }
}

impl Deref for TwoBlockSchema {
    type Target = TwoBlockTracker;
    fn deref(&self) -> &TwoBlockTracker {
        &self.tracker
    }
}

impl DerefMut for TwoBlockSchema {
    fn deref_mut(&mut self) -> &mut TwoBlockTracker {
        &mut self.tracker
    }
}

impl PerceptualSchema for TwoBlockSchema {
    type Percept = TwoBlockPercept;

    fn perceive(&mut self, inputs: &Inputs<'_>) -> TwoBlockPercept {
        let t = &mut self.tracker;
        let size = t.detector().size();
        match inputs.camera(self.camera) {
            Some(cam) => t
                .process(&cam.image, cam.stamp)
                .unwrap_or_else(|_| TwoBlockPercept::not_found(cam.stamp, t.model().mode(), size)),
            None => t.no_frame(inputs.now),
        }
    }
}
