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
    /// `[fiducial.two_block]` (see [`TwoBlockParams::from_profile`]).
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
