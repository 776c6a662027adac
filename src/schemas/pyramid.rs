//! RAPOSA's perceptual schema: the pyramid tracker of perception run on one camera of a
//! tick's [`Inputs`].

use super::{Inputs, Percept, PerceptualSchema};
use crate::perception::{PyramidPercept, PyramidTracker, PyramidTrackerParams, VisionError};
use crate::profile::Profile;
use std::ops::{Deref, DerefMut};

impl Percept for PyramidPercept {
    fn stamp(&self) -> f64 {
        self.stamp
    }
    /// Found when the orange guide is seen (blue alone is not the target).
    fn found(&self) -> bool {
        self.view.is_some()
    }
}

/// The pyramid perceptual schema: a [`PyramidTracker`] bound to one camera. It
/// dereferences to the tracker, so the tracker's methods (`process`, `bands`,
/// `set_bands`, `imprint_frame` …) are called on the schema directly.
///
/// # Example
///
/// A 40×30 frame on camera 0 with a 16 px blue frame around an orange disc of radius 5
/// centred at (18, 14), seen with f = 160 px: the 10 cm blue edges are 1 m away, and the
/// ball, 1.5 px left of the principal point, has a small bearing to the left. Resetting
/// the schema forgets the tracked ellipse.
///
/// ```
/// use marsupial::perception::{
///     ColorModelParams, HsvLimits, PyramidGeometry, PyramidParams, PyramidTrackerParams, RgbImage,
///     SegmentationMode,
/// };
/// use marsupial::schemas::{CameraInput, Inputs, Percept, PerceptualSchema, PyramidSchema};
///
/// let mut im = RgbImage::new(40, 30);
/// im.fill([120, 118, 115]);
/// for y in 6..22 {
///     for x in 10..26 {
///         if (x as f64 - 18.0).hypot(y as f64 - 14.0) <= 5.0 {
///             im.put(x, y, [235, 120, 20]);
///         } else if x < 12 || x >= 24 || y < 8 || y >= 20 {
///             im.put(x, y, [20, 60, 220]);
///         }
///     }
/// }
/// let params = PyramidTrackerParams {
///     width: 40,
///     height: 30,
///     detector: PyramidParams::default(),
///     geometry: PyramidGeometry { f_px: 160.0, principal: [20.0, 15.0], h: 0.1, m: 0.16, ball_diameter: 0.07 },
///     mode: SegmentationMode::Fixed,
///     colour: ColorModelParams {
///         n_sd: 4.0,
///         sd_floor: 0.01,
///         sd_ceiling: 0.2,
///         min_l: 20.0,
///         min_chroma: 0.0,
///         timeout1: 2.0,
///         timeout2: 5.0,
///         adaptive: false,
///         adapt_rate: 1.0,
///     },
///     limits: HsvLimits { n_sd: 4.0, hue_sd_deg: [1.0, 20.0], sv_sd: [0.01, 0.1], min_s: 0.2, min_v: 0.05 },
///     imprint_distance_m: 1.0,
///     imprint_widen: 1.5,
///     imprint_frames: 3,
/// };
/// let mut schema = PyramidSchema::new(0, &params);
/// let cameras = [Some(CameraInput { stamp: 0.1, image: im.view() })];
/// let p = schema.perceive(&Inputs { cameras: &cameras, ..Inputs::empty(0.1) });
/// assert!(p.found());
/// let v = p.view.unwrap();
/// assert!((v.blue_distance_m.unwrap() - 1.0).abs() < 1e-9);
/// assert!((v.bearing - (1.5f64 / 160.0).atan()).abs() < 1e-12);
/// assert_eq!(schema.detector().tracked(), Some([18.0, 14.0]));
/// schema.reset();
/// assert_eq!(schema.detector().tracked(), None);
///
/// assert!(!schema.perceive(&Inputs::empty(0.2)).found(), "no frame: nothing seen");
/// ```
#[derive(Debug, Clone)]
pub struct PyramidSchema {
    camera: usize,
    tracker: PyramidTracker,
}

impl PyramidSchema {
    /// The tracker built from `params`, reading camera `camera` of the inputs.
    pub fn new(camera: usize, params: &PyramidTrackerParams) -> Self {
        Self {
            camera,
            tracker: PyramidTracker::new(params),
        }
    }

    /// Builds the schema for camera `camera` of a profile with a `pyramid` fiducial
    /// (see [`PyramidTrackerParams::from_profile`]). Allocates only here.
    ///
    /// # Errors
    /// [`VisionError::Profile`] when the profile lacks the fiducial or the camera.
    pub fn from_profile(profile: &Profile, camera: usize) -> Result<Self, VisionError> {
        Ok(Self::new(camera, &PyramidTrackerParams::from_profile(profile, camera)?))
    }

    /// The camera index the schema reads.
    pub fn camera(&self) -> usize {
        self.camera
    }

    /// The tracker.
    pub fn tracker(&self) -> &PyramidTracker {
        &self.tracker
    }

    /// The tracker, mutable.
    pub fn tracker_mut(&mut self) -> &mut PyramidTracker {
        &mut self.tracker
    }
}

impl Deref for PyramidSchema {
    type Target = PyramidTracker;
    fn deref(&self) -> &PyramidTracker {
        &self.tracker
    }
}

impl DerefMut for PyramidSchema {
    fn deref_mut(&mut self) -> &mut PyramidTracker {
        &mut self.tracker
    }
}

impl PerceptualSchema for PyramidSchema {
    type Percept = PyramidPercept;

    fn perceive(&mut self, inputs: &Inputs<'_>) -> PyramidPercept {
        let t = &mut self.tracker;
        let size = t.detector().size();
        match inputs.camera(self.camera) {
            Some(cam) => t
                .process(&cam.image, cam.stamp)
                .unwrap_or_else(|_| PyramidPercept::not_found(cam.stamp, size)),
            None => t.no_frame(inputs.now),
        }
    }

    fn reset(&mut self) {
        self.tracker.reset_tracking();
    }
}
