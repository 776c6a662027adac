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

    /// Builds the schema for camera `camera` of a profile with a `[fiducial.pyramid]`
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
